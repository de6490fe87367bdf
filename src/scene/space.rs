//! The space a scene lives in: its dimension (planar or spatial) and its fixed body, the
//! reserved name [`GROUND`]. Below the scene's data model ([`super::model`], which re-exports
//! both) and the joint kinds' own fields, which check against them.

/// The reserved name of the fixed body.
pub const GROUND: &str = "ground";

/// Planar (2D) or spatial (3D) mechanism.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// `"dimension": 2`.
    Planar,
    /// `"dimension": 3`.
    Spatial,
}

impl Dimension {
    /// Number of coordinates of a point or vector: 2 or 3.
    pub fn coords(self) -> usize {
        match self {
            Dimension::Planar => 2,
            Dimension::Spatial => 3,
        }
    }

    /// Number of angular velocity components: 1 in the plane, 3 in space.
    pub fn rotations(self) -> usize {
        match self {
            Dimension::Planar => 1,
            Dimension::Spatial => 3,
        }
    }
}
