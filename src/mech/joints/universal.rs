//! Universal (Hooke's, Cardan) joint, spatial: the points coincide, `P_a − P_b = 0` (three
//! rows `x`, `y`, `z`), and the two fork axes stay perpendicular, `(R_a â_1)·(R_b â_2) = 0`
//! (row `cross`; `â_1` the unit fork axis in the first body's frame, `â_2` in the second's):
//! four rows, two relative rotations free (about each fork axis).
//!
//! Bond graph: each row's rate as a modulated sum of the inertias' junction flows into an
//! `Sf = 0` ([`crate::mech::annotate`] draws every spatial row so). Twin: a spring per axis on
//! `P_a − P_b` and a torsional one on the cross row. Reaction: the force at the cross and the
//! moment about the axis `R_a â_1 × R_b â_2`, on the second body.

use super::joint::{unit_axis, Ends, Glyph, Joint, RowWriter, Rows};
use crate::expr::Expr;
use crate::mech::error::MechError;

/// A Hooke's joint with fork axes `axes = [a1, a2]` (each in its own body's frame).
pub(super) struct Universal<'a> {
    pub(super) axes: &'a [Vec<f64>; 2],
}

impl Joint for Universal<'_> {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        if !w.spatial {
            return Err(MechError::at(
                &format!("{path}.type"),
                "a universal joint needs a spatial scene",
            ));
        }
        let u1 = unit_axis(&self.axes[0], &format!("{path}.axes[0]"))?;
        let u2 = unit_axis(&self.axes[1], &format!("{path}.axes[1]"))?;
        let mut rows = w.coincident(ends);
        let g = &mut *w.g;
        let ra = ends.ka.rotation3(g);
        let rb = ends.kb.rotation3(g);
        let mut world = |r: &[[Expr; 3]; 3], u: [f64; 3]| -> Vec<Expr> {
            let ue: Vec<Expr> = u.iter().map(|&c| g.constant(c)).collect();
            (0..3).map(|i| g.dot(&r[i], &ue)).collect()
        };
        let a1 = world(&ra, u1);
        let a2 = world(&rb, u2);
        rows.push(("cross", g.dot(&a1, &a2)));
        Ok(rows)
    }

    fn locks(&self, _spatial: bool) -> usize {
        4
    }

    fn transmits_moment(&self) -> bool {
        true
    }

    fn needs_rotation(&self, _end: usize, _spatial: bool) -> bool {
        true
    }

    fn glyph(&self) -> Glyph {
        Glyph::Ball
    }
}
