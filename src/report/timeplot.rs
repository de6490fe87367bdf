//! SVG plots against time of a run's columns (`bondmech plot RUN.csv`, `bondmech run --plot`):
//! one file per group of columns with one unit, the legend beside the plot (never over the
//! data), axes labelled with their units.
//!
//! | file | columns (by their last name part) | unit |
//! |---|---|---|
//! | `positions.svg` | `x`, `y`, `z` (centres and points) | m |
//! | `angles.svg` | `angle`, `psi`, `theta`, `phi` | rad |
//! | `velocities.svg` | `vx`, `vy`, `vz` | m/s |
//! | `angular_velocities.svg` | `omega`, `wx`, `wy`, `wz`, `wX`, `wY`, `wZ` | rad/s |
//! | `quaternions.svg` | `qw`, `qx`, `qy`, `qz` | 1 |
//! | `energy.svg` | `energy`, `kinetic_energy`, `potential_energy` | J |
//! | `constraint_error.svg` | `constraint_error` (log scale) | m, rad |
//! | `forces.svg` | `Fx`, `Fy`, `Fz` | N |
//! | `moments.svg` | `Mx`, `My`, `Mz` | N·m |
//! | `other.svg` | anything else | — |

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::plot::{plot_error, COLOURS};
use crate::solve::Solution;
use crate::{Error, Result};

/// A group of columns plotted in one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlotGroup {
    /// File stem (`positions`, `energy`, …).
    pub file: &'static str,
    /// What the y axis shows.
    pub quantity: &'static str,
    /// The unit of the y axis (`m`, `rad`, `J`, …); empty for none.
    pub unit: &'static str,
    /// Logarithmic y axis.
    pub log: bool,
}

const GROUPS: [PlotGroup; 10] = [
    PlotGroup {
        file: "positions",
        quantity: "position",
        unit: "m",
        log: false,
    },
    PlotGroup {
        file: "angles",
        quantity: "angle",
        unit: "rad",
        log: false,
    },
    PlotGroup {
        file: "velocities",
        quantity: "velocity",
        unit: "m/s",
        log: false,
    },
    PlotGroup {
        file: "angular_velocities",
        quantity: "angular velocity",
        unit: "rad/s",
        log: false,
    },
    PlotGroup {
        file: "quaternions",
        quantity: "attitude quaternion",
        unit: "1",
        log: false,
    },
    PlotGroup {
        file: "energy",
        quantity: "energy",
        unit: "J",
        log: false,
    },
    PlotGroup {
        file: "constraint_error",
        quantity: "largest |g(q)|",
        unit: "m, rad",
        log: true,
    },
    PlotGroup {
        file: "forces",
        quantity: "force",
        unit: "N",
        log: false,
    },
    PlotGroup {
        file: "moments",
        quantity: "moment",
        unit: "N·m",
        log: false,
    },
    PlotGroup {
        file: "other",
        quantity: "value",
        unit: "",
        log: false,
    },
];

/// The group a column belongs to, by the last part of its name.
pub fn plot_group(column: &str) -> PlotGroup {
    let last = column.rsplit('.').next().unwrap_or(column);
    let i = match last {
        "x" | "y" | "z" => 0,
        "angle" | "psi" | "theta" | "phi" => 1,
        "vx" | "vy" | "vz" => 2,
        "omega" | "wx" | "wy" | "wz" | "wX" | "wY" | "wZ" => 3,
        "qw" | "qx" | "qy" | "qz" => 4,
        "energy" | "kinetic_energy" | "potential_energy" => 5,
        "constraint_error" => 6,
        "Fx" | "Fy" | "Fz" => 7,
        "Mx" | "My" | "Mz" => 8,
        _ => 9,
    };
    GROUPS[i]
}

/// Writes one SVG per group of `sol`'s columns into `dir` (created when missing) and returns
/// the files written; `source` names the run in the titles.
pub fn plot_solution(sol: &Solution, source: &str, dir: &Path) -> Result<Vec<PathBuf>> {
    if sol.times.is_empty() {
        return Err(Error::Options(format!("{source}: no rows to plot")));
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::Io {
        path: dir.display().to_string(),
        source: e,
    })?;
    let mut written = Vec::new();
    for group in GROUPS {
        let cols: Vec<usize> = (0..sol.columns.len())
            .filter(|&c| plot_group(&sol.columns[c]) == group)
            .collect();
        if cols.is_empty() {
            continue;
        }
        let path = dir.join(format!("{}.svg", group.file));
        if Path::new(source) == path {
            return Err(Error::Options(format!(
                "{}: would overwrite the input; choose another --out directory",
                path.display()
            )));
        }
        plot_group_svg(sol, source, &group, &cols, &path)?;
        written.push(path);
    }
    Ok(written)
}

/// `[lo, hi]` of the finite values, padded; a constant gets a band around it.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    if !lo.is_finite() {
        return if log { (1e-16, 1.0) } else { (-1.0, 1.0) };
    }
    if log {
        let hi = if hi <= lo { lo * 10.0 } else { hi };
        return (lo / 2.0, hi * 2.0);
    }
    if hi - lo <= 1e-12 * lo.abs().max(hi.abs()) {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

fn plot_group_svg(
    sol: &Solution,
    source: &str,
    group: &PlotGroup,
    cols: &[usize],
    path: &Path,
) -> Result<()> {
    let err = |e| plot_error(path, e);
    let legend_w = 230u32;
    let height = (480u32).max(70 + 18 * cols.len() as u32);
    let root = SVGBackend::new(path, (760 + legend_w, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (plot_area, legend_area) = root.split_horizontally(760);
    let (t0, t1) = (sol.times[0], sol.times[sol.times.len() - 1]);
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let series: Vec<(String, Vec<(f64, f64)>)> = cols
        .iter()
        .map(|&c| {
            let pts = sol
                .times
                .iter()
                .zip(&sol.rows)
                .map(|(&t, r)| (t, r[c]))
                .filter(|(_, v)| v.is_finite() && (!group.log || *v > 0.0))
                .collect();
            (sol.columns[c].clone(), pts)
        })
        .collect();
    let (y0, y1) = range(
        series.iter().flat_map(|s| s.1.iter().map(|p| p.1)),
        group.log,
    );
    let y_desc = if group.unit.is_empty() {
        group.quantity.to_string()
    } else {
        format!("{} ({})", group.quantity, group.unit)
    };
    let title = format!("{source}: {}", group.file.replace('_', " "));
    let mut builder = ChartBuilder::on(&plot_area);
    builder
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80);
    let colour = |i: usize| COLOURS[i % COLOURS.len()];
    let width = |i: usize| if i < COLOURS.len() { 2 } else { 1 };
    if group.log {
        let mut chart = builder
            .build_cartesian_2d(t0..t1, (y0..y1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time t (s)")
            .y_desc(y_desc.clone())
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 15))
            .light_line_style(RGBColor(245, 245, 245))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(err)?;
        for (i, (_, pts)) in series.iter().enumerate() {
            chart
                .draw_series(LineSeries::new(
                    pts.clone(),
                    colour(i).stroke_width(width(i)),
                ))
                .map_err(err)?;
        }
    } else {
        let mut chart = builder.build_cartesian_2d(t0..t1, y0..y1).map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time t (s)")
            .y_desc(y_desc.clone())
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 15))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(err)?;
        for (i, (_, pts)) in series.iter().enumerate() {
            chart
                .draw_series(LineSeries::new(
                    pts.clone(),
                    colour(i).stroke_width(width(i)),
                ))
                .map_err(err)?;
        }
    }
    // the legend, beside the plot
    for (i, (name, _)) in series.iter().enumerate() {
        let y = 50 + 18 * i as i32;
        legend_area
            .draw(&PathElement::new(
                vec![(8, y), (36, y)],
                colour(i).stroke_width(width(i)),
            ))
            .map_err(err)?;
        legend_area
            .draw(&Text::new(
                name.clone(),
                (44, y - 7),
                ("sans-serif", 14).into_font().color(&BLACK),
            ))
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_group_by_their_unit() {
        assert_eq!(plot_group("bar2.A.x").unit, "m");
        assert_eq!(plot_group("bar1.angle").unit, "rad");
        assert_eq!(plot_group("b.theta").unit, "rad");
        assert_eq!(plot_group("b.wZ").unit, "rad/s");
        assert_eq!(plot_group("bar2.A.vy").unit, "m/s");
        assert_eq!(plot_group("energy").unit, "J");
        assert_eq!(plot_group("pivot.Fx").unit, "N");
        assert_eq!(plot_group("weld.Mz").unit, "N·m");
        assert_eq!(plot_group("b.qw").file, "quaternions");
        assert_eq!(plot_group("constraint_error").file, "constraint_error");
        assert_eq!(plot_group("something").file, "other");
    }

    #[test]
    fn ranges_pad_and_survive_constants() {
        assert_eq!(range([1.0, 1.0].into_iter(), false), (0.9, 1.1));
        assert_eq!(range([0.0].into_iter(), false), (-1.0, 1.0));
        let (lo, hi) = range([0.0, 10.0].into_iter(), false);
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
        assert_eq!(range([0.0, 1e-9].into_iter(), true), (5e-10, 2e-8));
    }
}
