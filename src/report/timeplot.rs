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

use super::error::{io_error, ReportError, Result};
use super::plot::{plot_error, COLOURS};
use crate::solve::Solution;

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

/// What to plot and how to title it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotOptions {
    /// The plots' title (the scene's name); empty: the source's file stem.
    pub title: String,
    /// The columns to draw: exact names, or a prefix ending in `*` (`bar2.*`); `None`: all.
    pub columns: Option<Vec<String>>,
}

/// Writes one SVG per group of `sol`'s columns into `dir` (created when missing) and returns
/// the files written; `source` names the run (errors, and the title when it has no other).
pub fn plot_solution(sol: &Solution, source: &str, dir: &Path) -> Result<Vec<PathBuf>> {
    plot_solution_with(sol, source, dir, &PlotOptions::default())
}

/// The columns `patterns` pick (exact names or `prefix*`), in the solution's order; a pattern
/// that picks nothing is an error naming it.
pub fn pick_columns(columns: &[String], patterns: &[String]) -> Result<Vec<usize>> {
    let matches = |p: &str, c: &str| match p.strip_suffix('*') {
        Some(prefix) => c.starts_with(prefix),
        None => p == c,
    };
    for p in patterns {
        if !columns.iter().any(|c| matches(p, c)) {
            let shown: Vec<&str> = columns.iter().take(12).map(String::as_str).collect();
            return Err(ReportError::UnknownColumn {
                pattern: p.clone(),
                shown: format!(
                    "{}{}",
                    shown.join(", "),
                    if columns.len() > 12 { ", …" } else { "" }
                ),
            });
        }
    }
    Ok((0..columns.len())
        .filter(|&c| patterns.iter().any(|p| matches(p, &columns[c])))
        .collect())
}

/// [`plot_solution`] with a title and a choice of columns.
pub fn plot_solution_with(
    sol: &Solution,
    source: &str,
    dir: &Path,
    opts: &PlotOptions,
) -> Result<Vec<PathBuf>> {
    if sol.times.is_empty() {
        return Err(ReportError::NoRows {
            origin: source.to_string(),
            purpose: "to plot",
        });
    }
    let picked = match &opts.columns {
        Some(p) => pick_columns(&sol.columns, p)?,
        None => (0..sol.columns.len()).collect(),
    };
    let title = if opts.title.is_empty() {
        Path::new(source)
            .file_stem()
            .map_or_else(|| source.to_string(), |s| s.to_string_lossy().into_owned())
    } else {
        opts.title.clone()
    };
    // every drawing's file first: the CSV drawn from never gets replaced by one (by path,
    // link or inode), and nothing is written when one would
    let mut drawings = Vec::new();
    for group in GROUPS {
        let cols: Vec<usize> = picked
            .iter()
            .copied()
            .filter(|&c| plot_group(&sol.columns[c]) == group)
            .collect();
        if cols.is_empty() {
            continue;
        }
        let path = dir.join(format!("{}.svg", group.file));
        if crate::output::same_file(Path::new(source), &path) {
            return Err(ReportError::WouldOverwrite {
                path: path.display().to_string(),
            });
        }
        drawings.push((group, cols, path));
    }
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))?;
    let mut written = Vec::new();
    for (group, cols, path) in drawings {
        plot_group_svg(sol, &title, &group, &cols, &path)?;
        written.push(path);
    }
    Ok(written)
}

/// `[lo, hi]` of the finite values, padded; a constant gets a band around it.
pub(crate) fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
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

/// A y axis that resolves small variations: values shown as `offset + scale × tick` when the
/// data vary by less than a thousandth of their size (energy conserved to 1e-9, say).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffsetScale {
    /// Subtracted from every value.
    pub offset: f64,
    /// The unit of the ticks.
    pub scale: f64,
}

impl OffsetScale {
    /// The offset and scale for data in `[lo, hi]` (`None`: plain ticks suffice).
    pub fn for_range(lo: f64, hi: f64) -> Option<OffsetScale> {
        let range = hi - lo;
        let size = lo.abs().max(hi.abs());
        // small against the values (a conserved energy) or small in itself (a drift near 0)
        if !(range > 0.0 && range.is_finite()) || (range >= 1e-3 * size && size >= 1e-3) {
            return None;
        }
        let e = range.log10().floor();
        let scale = 10f64.powf(e);
        // the offset keeps the digits above the varying ones
        let unit = 10f64.powf(e + 1.0);
        let offset = ((lo + hi) / 2.0 / unit).round() * unit;
        Some(OffsetScale { offset, scale })
    }

    /// `−29.43 + 1e-8 ×`.
    pub fn label(&self) -> String {
        let decimals = (-(self.scale.log10().round()) - 1.0).max(0.0) as usize;
        let mut o = format!("{:.decimals$}", self.offset);
        if o.contains('.') {
            o = o.trim_end_matches('0').trim_end_matches('.').to_string();
        }
        let o = if o == "-0" {
            "0".to_string()
        } else {
            o.replace('-', "−")
        };
        let sc = format!("{:e}", self.scale);
        if self.offset == 0.0 {
            format!("{sc} ×")
        } else {
            format!("{o} + {sc} ×")
        }
    }
}

/// A tick label with as many decimals as the ticks' spacing needs (never `-0.0`).
pub(crate) fn tick_label(v: f64, lo: f64, hi: f64) -> String {
    // plotters draws about ten ticks
    let step = (hi - lo).abs() / 10.0;
    let decimals = if step > 0.0 && step.is_finite() {
        (-step.log10()).ceil().clamp(0.0, 12.0) as usize
    } else {
        2
    };
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// The colour of series `i` in a plot: tab10 first, then hues by the golden angle at three
/// lightnesses, so that no two series of a plot share a colour.
pub fn series_colour(i: usize) -> RGBColor {
    if i < COLOURS.len() {
        return COLOURS[i];
    }
    let j = i - COLOURS.len();
    let h = (j as f64 * 137.507_764_05 + 15.0) % 360.0;
    let l = [0.42, 0.30, 0.55][j % 3];
    let s = 0.75;
    // HSL → RGB
    let c = (1.0 - (2.0 * l - 1.0f64).abs()) * s;
    let hp = h / 60.0;
    let x = c * (1.0 - (hp % 2.0 - 1.0).abs());
    let (r, g, b) = match hp as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = l - c / 2.0;
    let v = |u: f64| ((u + m) * 255.0).round().clamp(0.0, 255.0) as u8;
    RGBColor(v(r), v(g), v(b))
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
    // tiny variations on a large value: plot (v − offset) / scale
    let (lo, hi) = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p.1))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    let shift = if group.log {
        None
    } else {
        OffsetScale::for_range(lo, hi)
    };
    let series: Vec<(String, Vec<(f64, f64)>)> = match shift {
        Some(os) => series
            .into_iter()
            .map(|(n, pts)| {
                let pts = pts
                    .into_iter()
                    .map(|(t, v)| (t, (v - os.offset) / os.scale))
                    .collect();
                (n, pts)
            })
            .collect(),
        None => series,
    };
    let (y0, y1) = range(
        series.iter().flat_map(|s| s.1.iter().map(|p| p.1)),
        group.log,
    );
    let mut y_desc = if group.unit.is_empty() {
        group.quantity.to_string()
    } else {
        format!("{} ({})", group.quantity, group.unit)
    };
    if let Some(os) = shift {
        y_desc = format!("{y_desc} = {}", os.label());
    }
    let title = format!("{source}: {}", group.file.replace('_', " "));
    let title = if series.len() > 1 {
        title
    } else {
        format!("{title} ({})", series[0].0)
    };
    let mut builder = ChartBuilder::on(&plot_area);
    builder
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80);
    let colour = series_colour;
    let width = |_: usize| 2;
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
            .y_label_formatter(&|v| tick_label(*v, y0, y1))
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
    fn small_variations_get_an_offset_and_a_scale() {
        let os = OffsetScale::for_range(-29.430000004, -29.429999997).unwrap();
        assert_eq!(os.scale, 1e-9);
        assert!((os.offset + 29.43).abs() < 1e-12, "{os:?}");
        assert_eq!(os.label(), "−29.43 + 1e-9 ×");
        assert_eq!(OffsetScale::for_range(0.0, 1.0), None);
        assert_eq!(tick_label(-0.00001, -1.0, 1.0), "0.0");
        assert_eq!(tick_label(0.25, 0.0, 1.0), "0.2");
        assert_eq!(tick_label(0.0026, 0.0, 0.01), "0.003");
        let near_zero = OffsetScale::for_range(-4e-6, 1e-6).unwrap();
        assert_eq!((near_zero.offset, near_zero.scale), (0.0, 1e-6));
        let c: std::collections::BTreeSet<(u8, u8, u8)> = (0..100)
            .map(|i| {
                let c = series_colour(i);
                (c.0, c.1, c.2)
            })
            .collect();
        assert_eq!(c.len(), 100, "no colour repeats within 100 series");
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
