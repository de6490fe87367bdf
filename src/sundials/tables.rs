//! Butcher tables handed to ARKODE's explicit Runge–Kutta stepper beyond its built-in ones.
//!
//! Tsitouras 5(4) (Ch. Tsitouras, "Runge–Kutta pairs of order 5(4) satisfying only the first
//! column simplifying assumption", Computers & Mathematics with Applications 62 (2011)
//! 770–775, Table 1): seven stages, the last one at the step's end with the solution's weights
//! (first same as last: six right-hand sides per step), order 5 with an embedded order 4, and
//! smaller principal error coefficients than Dormand–Prince 5(4) at the same cost. Its order
//! conditions are checked in `tests/sundials_erk.rs`.

/// An explicit Runge–Kutta method with an embedding: `c`, `A` (row-major, strictly lower),
/// `b`, the embedding's weights `d`, their orders `q` and `p`.
#[derive(Clone, Debug, PartialEq)]
pub struct ButcherTable {
    /// Name (summaries, benches).
    pub name: &'static str,
    /// Method order.
    pub q: i32,
    /// Embedding order.
    pub p: i32,
    /// Nodes.
    pub c: Vec<f64>,
    /// Coefficients, `s × s` row-major.
    pub a: Vec<f64>,
    /// Weights of the solution.
    pub b: Vec<f64>,
    /// Weights of the embedding.
    pub d: Vec<f64>,
}

impl ButcherTable {
    /// Number of stages.
    pub fn stages(&self) -> usize {
        self.c.len()
    }

    /// Tsitouras 5(4) (see the module documentation).
    pub fn tsitouras5() -> ButcherTable {
        let c = vec![0.0, 0.161, 0.327, 0.9, 0.9800255409045097, 1.0, 1.0];
        let rows: [&[f64]; 7] = [
            &[],
            &[0.161],
            &[-0.008480655492356989, 0.335480655492357],
            &[2.8971530571054935, -6.359448489975075, 4.3622954328695815],
            &[
                5.325864828439257,
                -11.748883564062828,
                7.4955393428898365,
                -0.09249506636175525,
            ],
            &[
                5.86145544294642,
                -12.92096931784711,
                8.159367898576159,
                -0.071584973281401,
                -0.028269050394068383,
            ],
            &[
                0.09646076681806523,
                0.01,
                0.4798896504144996,
                1.379008574103742,
                -3.290069515436081,
                2.324710524099774,
            ],
        ];
        let s = c.len();
        let mut a = vec![0.0; s * s];
        for (i, row) in rows.iter().enumerate() {
            a[i * s..i * s + row.len()].copy_from_slice(row);
        }
        let b: Vec<f64> = rows[6].iter().copied().chain([0.0]).collect();
        // the embedding from the published differences b − d
        let diff = [
            -0.0017800110522257772,
            -0.0008164344596567469,
            0.007880878010261995,
            -0.1447110071732629,
            0.5823571654525552,
            -0.45808210592918697,
            1.0 / 66.0,
        ];
        let d = b.iter().zip(diff).map(|(b, e)| b - e).collect();
        ButcherTable {
            name: "Tsitouras 5(4)",
            q: 5,
            p: 4,
            c,
            a,
            b,
            d,
        }
    }
}
