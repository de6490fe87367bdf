//! The tables the commands print: a few rows of a run ([`short_table`], `bondmech run
//! --table`), the linear model's modes ([`LinearModel::table`], `bondmech linearize`) and the
//! static equilibrium's coordinates, reactions and drivers' efforts with its stiffness
//! eigenvalues ([`Equilibrium::table`], `bondmech equilibrium`).

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::linear_model::LinearModel;
use crate::solve::Solution;

/// About `rows` evenly spaced rows of the first few columns.
pub fn short_table(sol: &Solution, rows: usize) -> String {
    let cols: Vec<usize> = (0..sol.columns.len().min(6)).collect();
    let mut s = format!("{:>8}", "t");
    for &c in &cols {
        s.push_str(&format!(" {:>14}", sol.columns[c]));
    }
    s.push('\n');
    let n = sol.times.len();
    let stride = (n.max(2) - 1).div_ceil(rows.max(2) - 1).max(1);
    for k in (0..n).step_by(stride).chain(std::iter::once(n - 1)) {
        if k % stride != 0 && k != n - 1 {
            continue;
        }
        s.push_str(&format!("{:>8.3}", sol.times[k]));
        for &c in &cols {
            s.push_str(&format!(" {:>14.6}", sol.rows[k][c]));
        }
        s.push('\n');
        if k == n - 1 {
            break;
        }
    }
    s
}

impl LinearModel {
    /// A readable table of the modes (what `bondmech linearize` prints).
    pub fn table(&self) -> String {
        let mut t = format!(
            "linear model at {} (t = {}): {} states [{}], {} inputs [{}], {} outputs\n",
            self.at,
            self.t,
            self.states.len(),
            self.states.join(", "),
            self.inputs.len(),
            self.inputs.join(", "),
            self.outputs.len()
        );
        for n in &self.notes {
            t.push_str(&format!("note: {n}\n"));
        }
        t.push_str(&format!("CPU {:.3e} s\n", self.cpu_seconds));
        if !self.equilibrium {
            t.push_str("eigenvalues of A (1/s), about a moving operating point:\n");
            for (re, im) in &self.eigenvalues {
                t.push_str(&format!("  {re:+.6e} {im:+.6e}i\n"));
            }
            return t;
        }
        t.push_str(&format!(
            "{:>4}  {:>24}  {:>14}  {:>14}  {:>12}  {:>4}  shape\n",
            "mode", "eigenvalue (1/s)", "omega_n (rad/s)", "frequency (Hz)", "damping", "mult"
        ));
        for (k, m) in self.modes.iter().enumerate() {
            let ev = if m.eigenvalue.1 == 0.0 {
                format!("{:.6e}", m.eigenvalue.0)
            } else {
                format!("{:.4e} ± {:.4e}i", m.eigenvalue.0, m.eigenvalue.1)
            };
            let zeta = m
                .damping_ratio
                .map_or_else(|| "-".to_string(), |z| format!("{z:.6}"));
            let shape: Vec<String> = m
                .shape
                .iter()
                .filter(|(_, c)| c.norm() > 1e-9)
                .map(|(n, c)| {
                    if c.im.abs() <= 1e-9 * c.norm() {
                        format!("{n} {:.4}", c.re)
                    } else {
                        format!("{n} {:.4}{:+.4}i", c.re, c.im)
                    }
                })
                .collect();
            t.push_str(&format!(
                "{:>4}  {:>24}  {:>14.6}  {:>14.6}  {:>12}  {:>4}  {}\n",
                k + 1,
                ev,
                m.omega_n,
                m.frequency_hz,
                zeta,
                m.multiplicity,
                shape.join(", ")
            ));
        }
        t
    }
}

impl Equilibrium {
    /// A readable table of the equilibrium (what `bondmech equilibrium` prints): whether
    /// Newton converged and in how many iterations, the residual, stability, then the
    /// coordinates, reactions and drivers' efforts, and the reduced stiffness's eigenvalues.
    pub fn table(&self) -> String {
        let mut t = format!(
            "equilibrium: {} after {} iterations (residual {:.3e}), {}\n",
            if self.converged {
                "converged"
            } else {
                "not converged"
            },
            self.iterations,
            self.residual,
            self.stability.name()
        );
        for (what, list) in [
            ("coordinates", &self.coordinates),
            ("reactions", &self.reactions),
            ("drivers", &self.drivers),
        ] {
            if !list.is_empty() {
                t.push_str(&format!("{what}:\n"));
                for (k, v) in list {
                    t.push_str(&format!("  {k:<24} {v:>22.15e}\n"));
                }
            }
        }
        t.push_str(&format!(
            "stiffness eigenvalues (ω² = generalized eigenvalues of K_r and M_r on the DOF, 1/s²): {:?}\n",
            self.stiffness_eigenvalues
        ));
        t.push_str(&format!("CPU {:.3e} s\n", self.cpu_seconds));
        t
    }
}
