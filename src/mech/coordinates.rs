//! A mechanism being built, as data: the scene, its bodies' coordinates, velocities, inertias
//! and kinematics over one expression arena (the slot layout `[t, q, v]`), and the look-ups of
//! bodies and points by name. The layout of the bodies' states ([`super::layout`]), the joints'
//! closure rows ([`super::joints`]) and the assembly of the system ([`super::geometry`]) are
//! written on it; it knows none of them.

use std::collections::HashMap;

use super::body::{BodyKinematics, PointKinematics};
use super::error::MechError;
use super::system::{Coordinate, LoadTerm};
use crate::expr::ExprGraph;
use crate::scene::{Dimension, Inertia, PointRef, Scene};

/// Builds a mechanism's geometry (bodies, joints, names) over one expression arena.
pub(super) struct Geometry<'a> {
    pub(super) scene: &'a Scene,
    pub(super) spatial: bool,
    pub(super) g: ExprGraph,
    pub(super) coords: Vec<Coordinate>,
    pub(super) vels: Vec<Coordinate>,
    pub(super) mass: Vec<f64>,
    /// per scene body
    pub(super) kin: Vec<BodyKinematics>,
    pub(super) warnings: Vec<String>,
    /// Loads given as expressions, one term per component.
    pub(super) load_terms: Vec<LoadTerm>,
    /// Index in `scene.bodies` of each body name (the first body of that name), so that
    /// looking a joint's bodies up is not a scan of all bodies (quadratic in a chain's size).
    body_by_name: HashMap<&'a str, usize>,
    /// Each body's named points by name (built for bodies with many points only), so that
    /// looking 40 000 points up is not quadratic.
    points_by_name: Vec<Option<HashMap<&'a str, usize>>>,
}

impl<'a> Geometry<'a> {
    pub(super) fn new(scene: &'a Scene) -> Self {
        let mut body_by_name = HashMap::new();
        for (i, b) in scene.bodies.iter().enumerate() {
            body_by_name.entry(b.name.as_str()).or_insert(i);
        }
        let points_by_name = scene
            .bodies
            .iter()
            .map(|b| {
                (b.points.len() > 16).then(|| {
                    let mut m = HashMap::with_capacity(b.points.len());
                    for (k, (n, _)) in b.points.iter().enumerate() {
                        m.entry(n.as_str()).or_insert(k);
                    }
                    m
                })
            })
            .collect();
        Geometry {
            points_by_name,
            scene,
            spatial: matches!(scene.dimension, Dimension::Spatial),
            g: ExprGraph::new(),
            coords: Vec::new(),
            vels: Vec::new(),
            mass: Vec::new(),
            kin: Vec::new(),
            warnings: Vec::new(),
            load_terms: Vec::new(),
            body_by_name,
        }
    }

    pub(super) fn dim(&self) -> usize {
        if self.spatial {
            3
        } else {
            2
        }
    }

    /// Point coordinates of a reference on body `body` ("ground" or a scene body).
    pub(super) fn point_coords(
        &self,
        body: &str,
        p: &PointRef,
        path: &str,
    ) -> Result<Vec<f64>, MechError> {
        match p {
            PointRef::Coords(c) => Ok(c.clone()),
            PointRef::Named(n) => {
                let bi = *self
                    .body_by_name
                    .get(body)
                    .ok_or_else(|| MechError::at(path, format!("unknown body '{body}'")))?;
                let b = &self.scene.bodies[bi];
                match &self.points_by_name[bi] {
                    Some(m) => m.get(n.as_str()).map(|&k| b.points[k].1.clone()),
                    None => b
                        .points
                        .iter()
                        .find(|(pn, _)| pn == n)
                        .map(|(_, c)| c.clone()),
                }
                .ok_or_else(|| MechError::at(path, format!("body '{body}' has no point '{n}'")))
            }
        }
    }

    pub(super) fn body_index(&self, name: &str, path: &str) -> Result<Option<usize>, MechError> {
        if name == "ground" {
            return Ok(None);
        }
        self.body_by_name
            .get(name)
            .copied()
            .map(Some)
            .ok_or_else(|| MechError::at(path, format!("unknown body '{name}'")))
    }

    pub(super) fn kin_of(&self, body: &str, path: &str) -> Result<BodyKinematics, MechError> {
        Ok(match self.body_index(body, path)? {
            None => BodyKinematics::Ground,
            Some(i) => self.kin[i].clone(),
        })
    }

    pub(super) fn point(
        &mut self,
        body: &str,
        p: &PointRef,
        path: &str,
    ) -> Result<PointKinematics, MechError> {
        let c = self.point_coords(body, p, path)?;
        if c.len() != self.dim() {
            return Err(MechError::at(
                path,
                format!("point needs {} coordinates, got {}", self.dim(), c.len()),
            ));
        }
        let k = self.kin_of(body, path)?;
        Ok(k.point(&mut self.g, &c))
    }

    pub(super) fn initial_slots(&self) -> Vec<f64> {
        let mut x = vec![0.0];
        x.extend(self.coords.iter().map(|c| c.initial));
        x.extend(self.vels.iter().map(|c| c.initial));
        x
    }
}

pub(super) fn coord(body: &str, what: &str, initial: f64) -> Coordinate {
    Coordinate {
        name: format!("{body}.{what}"),
        initial,
    }
}

pub(super) fn planar_inertia(i: &Inertia) -> f64 {
    match i {
        Inertia::Planar(j) => *j,
        Inertia::Principal(j) => j[2],
    }
}
