//! Mechanisms from the chapter: bodies, joints, springs and loads, drawn as the bond graph
//! whose equations every formulation solves.
//!
//! * [`body`]: the kinematics of planar (16.3, 16.8) and spatial (16.1–16.2) bodies.
//! * [`annotate`]: the pinned bond graph completed (displacements, closures, slider and
//!   spring fragments) and read as the [`MultibodySystem`] the solver solves.
//! * [`geometry`]: the slot layout, the names expressions may use, the load terms, each
//!   joint's rows and how its reaction is read; written on
//!   * `coordinates`: the mechanism being built, as data (the slots, the look-ups by name),
//!   * `layout`: the bodies' coordinates, velocities and inertias (what the scene needs),
//!   * [`joints`]: each joint kind's closure rows `g_k(q)`, one file per kind,
//!   * `columns`: the output columns, the energy and the events.
//! * [`system`]: the system `q' = K(q) v`, `M v' = Q − G_vᵀ λ`, `g(q) = 0`.
//! * [`reactions`]: joint forces and moments from the constraint forces.

pub mod annotate;
pub mod body;
pub mod bondgraph;
mod columns;
mod coordinates;
mod error;
pub mod geometry;
pub mod joints;
mod layout;
pub mod reactions;
pub mod size;
pub mod system;

pub use annotate::{build, scene_bond_graph, Variant};
pub use error::MechError;
pub use reactions::JointReaction;
pub use system::{
    ConstraintRow, Coordinate, DriverOutput, EquationSource, EventFunction, JointViolation,
    LoadTerm, MultibodySystem, NonFiniteValue, OutputColumn,
};
