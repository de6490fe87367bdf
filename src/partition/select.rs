//! The choice of dependent velocities (or coordinates): the columns of the velocity (or
//! position) Jacobian that hold the constraint rows best, the causality's pivots first.

use nalgebra::DMatrix;

/// Picks `nc` columns of `G_v` by Gram–Schmidt with column pivoting (largest remaining norm
/// first), taking the `preferred` columns first and the others only when the preferred ones
/// cannot complete the set. Returns `None` when `G_v` has lower rank than its number of rows.
///
/// The preference reproduces the seed's causality pattern (16.5, 16.7): the joints force the
/// translational inertias into differential causality, while the rotations — on which the
/// MTF moduli depend — keep integral causality and become the independent coordinates.
pub fn select_dependent(gv: &DMatrix<f64>, preferred: &[bool]) -> Option<Vec<usize>> {
    let (m, n) = gv.shape();
    let mut cols: Vec<nalgebra::DVector<f64>> = (0..n).map(|j| gv.column(j).into_owned()).collect();
    let scale = cols
        .iter()
        .map(|c| c.norm())
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let mut chosen = Vec::with_capacity(m);
    // a column is usable when what is left of it after projection is not negligible
    let usable = 1e-3 * scale;
    for _ in 0..m {
        let pick = |pref_only: bool, chosen: &Vec<usize>, cols: &Vec<nalgebra::DVector<f64>>| {
            (0..n)
                .filter(|j| {
                    !chosen.contains(j)
                        && (!pref_only || preferred.get(*j).copied().unwrap_or(false))
                })
                .map(|j| (j, cols[j].norm()))
                .filter(|&(_, nrm)| nrm > usable)
                .fold(None, |a: Option<(usize, f64)>, b| match a {
                    Some(x) if x.1 >= b.1 => Some(x),
                    _ => Some(b),
                })
        };
        let (best, norm) = pick(true, &chosen, &cols).or_else(|| pick(false, &chosen, &cols))?;
        if norm <= 1e-10 * scale {
            return None;
        }
        chosen.push(best);
        let u = cols[best].clone() / norm;
        for c in cols.iter_mut() {
            let p = u.dot(c);
            *c -= &u * p;
        }
    }
    chosen.sort_unstable();
    Some(chosen)
}
