//! Distance (planar and spatial): a massless rigid link keeps the points `P_a`, `P_b` at the
//! distance `L`, one row `g = |P_b − P_a| − L = 0` (row `length`), `L` the scene's `length` or,
//! by default, the points' initial distance.
//!
//! Bond graph: the row's rate `ġ = (P_b − P_a)·(V_b − V_a) / |P_b − P_a|`, the ends' relative
//! velocity along the link, as a modulated sum of the inertias' junction flows into an
//! `Sf = 0` ([`crate::mech::annotate`] draws it from the closure). Twin: `k g`, a linear spring
//! of stiffness `k` and rest length `L` along the link. Reaction: the link's force on the
//! second body, along the link; its magnitude is the link's tension (no moment: both ends turn
//! freely).

use super::joint::{Ends, Glyph, Joint, RowWriter, Rows};
use crate::expr::Expr;
use crate::mech::error::MechError;

/// A rigid link of length `length` (`None`: the initial distance).
pub(super) struct Distance {
    pub(super) length: Option<f64>,
}

impl Joint for Distance {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        let g = &mut *w.g;
        let d: Vec<Expr> = (0..ends.pa.position.len())
            .map(|k| g.sub(ends.pb.position[k], ends.pa.position[k]))
            .collect();
        let d2 = g.dot(&d, &d);
        let distance = g.sqrt(d2);
        if g.eval(distance, w.x0) <= 0.0 {
            return Err(MechError::at(
                &format!("{path}.points"),
                "the link's two points coincide at the start (its direction is undefined); place them apart",
            ));
        }
        let length = match self.length {
            Some(l) => l,
            None => g.eval(distance, w.x0),
        };
        let l = g.constant(length);
        Ok(vec![("length", g.sub(distance, l))])
    }

    fn locks(&self, _spatial: bool) -> usize {
        1
    }

    fn transmits_moment(&self) -> bool {
        false
    }

    fn glyph(&self) -> Glyph {
        Glyph::Pin
    }
}
