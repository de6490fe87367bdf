//! SVG plots of a [`SweepReport`] (with `plotters`): error against CPU time (log-log, one line
//! per formulation, every point labelled with its relative tolerance) and error, constraint
//! violation and cost against the joint stiffness `k`. Legends sit in a column right of the
//! plotting area, never over the data; every axis names its unit.

use std::path::Path;

use plotters::prelude::*;

use super::error::{ReportError, Result};
use super::sweep::{SweepReport, WorkPoint};

/// The plots' colour cycle (matplotlib's "tab10").
pub(crate) const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// A plotting failure as an I/O error on the file being drawn.
pub(crate) fn plot_error(path: &Path, e: impl std::fmt::Display) -> ReportError {
    ReportError::Io {
        path: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// `[lo, hi]` of the positive finite values, widened a little (log axes need lo > 0).
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return (1e-16, 1.0);
    }
    let hi = if hi <= lo { lo * 10.0 } else { hi };
    (lo / 2.0, hi * 2.0)
}

/// Width of the legend column right of the plots.
pub(crate) const LEGEND_WIDTH: u32 = 230;

/// A line sample and its name, drawn as a legend entry.
pub(crate) type LegendEntry = (String, ShapeStyle);

/// Draws `entries` in the legend column `area`, from `top` down.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    entries: &[LegendEntry],
    top: i32,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for (i, (name, style)) in entries.iter().enumerate() {
        let y = top + 20 * i as i32;
        area.draw(&PathElement::new(vec![(6, y), (34, y)], *style))?;
        area.draw(&Circle::new((20, y), 3, style.color.filled()))?;
        area.draw(&Text::new(
            name.clone(),
            (42, y - 7),
            ("sans-serif", 14).into_font().color(&BLACK),
        ))?;
    }
    Ok(())
}

/// A tolerance as a short label: `1e-6`, `3e-9`.
fn tolerance_label(rtol: f64) -> String {
    let s = format!("{rtol:.0e}");
    s.replace("e-0", "e-")
}

fn usable(w: &WorkPoint) -> bool {
    w.failure.is_none() && w.error.is_finite() && w.error > 0.0 && w.cpu_seconds > 0.0
}

/// Error against CPU time, log-log, one line per series, each point labelled with its `rtol`.
pub fn work_precision_svg(report: &SweepReport, path: &Path) -> Result<()> {
    let err = |e| plot_error(path, e);
    // a series whose points all failed is left out of the plot and its legend
    let pts: Vec<&WorkPoint> = report.work_precision.iter().filter(|w| usable(w)).collect();
    let mut series: Vec<&str> = Vec::new();
    for w in &pts {
        if !series.contains(&w.series.as_str()) {
            series.push(&w.series);
        }
    }
    let (x0, x1) = log_range(pts.iter().map(|w| w.cpu_seconds));
    let (y0, y1) = log_range(pts.iter().map(|w| w.error));
    let root = SVGBackend::new(path, (800 + LEGEND_WIDTH, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (plot_area, legend_area) = root.split_horizontally(800);
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(
            format!(
                "{}: work-precision (t_end = {} s)",
                report.scene, report.t_end
            ),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("CPU time per solve, median (s)")
        .y_desc("largest error vs reference (m, rad)")
        .axis_desc_style(("sans-serif", 15))
        .label_style(("sans-serif", 13))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    let mut legend: Vec<LegendEntry> = Vec::new();
    let mut placed: Vec<(i32, i32)> = Vec::new();
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let mut line: Vec<(f64, f64, f64)> = pts
            .iter()
            .filter(|w| w.series == *s)
            .map(|w| (w.cpu_seconds, w.error, w.rtol))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(
                line.iter().map(|p| (p.0, p.1)),
                colour.stroke_width(2),
            ))
            .map_err(err)?;
        chart
            .draw_series(
                line.iter()
                    .map(|&(x, y, _)| Circle::new((x, y), 3, colour.filled())),
            )
            .map_err(err)?;
        // each point's rtol beside it, at the first free place (skipped when all are taken)
        for &(x, y, rtol) in &line {
            let (px, py) = chart.backend_coord(&(x, y));
            let free = [(5, -13), (5, 3), (-32, -13), (-32, 3)]
                .into_iter()
                .find(|&(dx, dy)| {
                    let (lx, ly) = (px + dx, py + dy);
                    !placed
                        .iter()
                        .any(|&(ox, oy): &(i32, i32)| (ox - lx).abs() < 30 && (oy - ly).abs() < 12)
                });
            if let Some((dx, dy)) = free {
                placed.push((px + dx, py + dy));
                chart
                    .plotting_area()
                    .draw(
                        &(EmptyElement::at((x, y))
                            + Text::new(
                                tolerance_label(rtol),
                                (dx, dy),
                                ("sans-serif", 11).into_font().color(&colour),
                            )),
                    )
                    .map_err(err)?;
            }
        }
        legend.push((s.to_string(), colour.stroke_width(2)));
    }
    legend_area
        .draw(&Text::new(
            "points: rtol",
            (8, 40),
            ("sans-serif", 13).into_font().color(&BLACK),
        ))
        .map_err(err)?;
    draw_legend(&legend_area, &legend, 72).map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Two panels against the joint stiffness k (log-log): error vs the DAE reference and the spring
/// stretch (top); CPU time and steps relative to the GGL DAE at the same tolerance (bottom).
pub fn stiffness_svg(report: &SweepReport, path: &Path) -> Result<()> {
    let err = |e| plot_error(path, e);
    let pts: Vec<_> = report
        .stiffness
        .iter()
        .filter(|p| p.run.failure.is_none())
        .collect();
    let root = SVGBackend::new(path, (800 + LEGEND_WIDTH, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (plots, legend_area) = root.split_horizontally(800);
    let (legend_top, legend_bottom) = legend_area.split_vertically(400);
    let (top, bottom) = plots.split_vertically(400);
    let (k0, k1) = log_range(report.stiffness.iter().map(|p| p.run.joint_stiffness));

    let mut up_values: Vec<f64> = pts.iter().map(|p| p.run.error).collect();
    up_values.extend(pts.iter().map(|p| p.run.max_constraint_error));
    up_values.push(report.accuracy);
    up_values.push(report.dae_baseline.error);
    let (e0, e1) = log_range(up_values.into_iter());
    let mut chart = ChartBuilder::on(&top)
        .caption(
            format!(
                "{}: decoupled twin vs spring rigidity (rtol {:e})",
                report.scene, report.stiffness_rtol
            ),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((k0..k1).log_scale(), (e0..e1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("joint stiffness k (N/m)")
        .y_desc("error (m, rad), stretch (m)")
        .axis_desc_style(("sans-serif", 15))
        .label_style(("sans-serif", 13))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    type Line<'a> = (&'a str, RGBColor, Vec<(f64, f64)>);
    let lines: [Line; 2] = [
        (
            "error vs DAE reference",
            COLOURS[0],
            pts.iter()
                .filter(|p| p.run.error > 0.0)
                .map(|p| (p.run.joint_stiffness, p.run.error))
                .collect(),
        ),
        (
            "spring stretch max|g|",
            COLOURS[1],
            pts.iter()
                .filter(|p| p.run.max_constraint_error > 0.0)
                .map(|p| (p.run.joint_stiffness, p.run.max_constraint_error))
                .collect(),
        ),
    ];
    let mut legend: Vec<LegendEntry> = Vec::new();
    for (label, colour, line) in lines {
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(err)?;
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
        legend.push((label.to_string(), colour.stroke_width(2)));
    }
    let acc = report.accuracy;
    chart
        .draw_series(LineSeries::new(
            vec![(k0, acc), (k1, acc)],
            COLOURS[3].stroke_width(1),
        ))
        .map_err(err)?;
    legend.push((
        format!("requested accuracy {acc:.0e}"),
        COLOURS[3].stroke_width(1),
    ));
    draw_legend(&legend_top, &legend, 60).map_err(err)?;

    let base_cpu = report.dae_baseline.cpu_seconds;
    let base_steps = report.dae_baseline.steps.max(1) as f64;
    let cpu: Vec<(f64, f64)> = pts
        .iter()
        .map(|p| (p.run.joint_stiffness, p.run.cpu_seconds / base_cpu))
        .filter(|(_, r)| r.is_finite() && *r > 0.0)
        .collect();
    let steps: Vec<(f64, f64)> = pts
        .iter()
        .map(|p| (p.run.joint_stiffness, p.run.steps as f64 / base_steps))
        .filter(|(_, r)| *r > 0.0)
        .collect();
    let (r0, r1) = log_range(
        cpu.iter()
            .chain(&steps)
            .map(|p| p.1)
            .chain(std::iter::once(1.0)),
    );
    let mut chart = ChartBuilder::on(&bottom)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((k0..k1).log_scale(), (r0..r1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("joint stiffness k (N/m)")
        .y_desc("cost / GGL DAE cost (ratio)")
        .axis_desc_style(("sans-serif", 15))
        .label_style(("sans-serif", 13))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .draw()
        .map_err(err)?;
    let mut legend: Vec<LegendEntry> = Vec::new();
    for (label, colour, line) in [
        ("CPU time / DAE", COLOURS[2], cpu),
        ("steps / DAE", COLOURS[4], steps),
    ] {
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(err)?;
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
        legend.push((label.to_string(), colour.stroke_width(2)));
    }
    chart
        .draw_series(LineSeries::new(
            vec![(k0, 1.0), (k1, 1.0)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
    legend.push(("GGL DAE (= 1)".to_string(), BLACK.stroke_width(1)));
    draw_legend(&legend_bottom, &legend, 40).map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::sweep::StiffnessPoint;

    fn point(series: &str, k: f64, rtol: f64, error: f64, cpu: f64) -> WorkPoint {
        WorkPoint {
            series: series.into(),
            formulation: series.into(),
            joint_stiffness: k,
            rtol,
            atol: rtol / 100.0,
            error,
            cpu_seconds: cpu,
            cpu_seconds_min: cpu,
            steps: 100,
            residual_evals: 200,
            jacobian_evals: 10,
            error_test_failures: 1,
            max_constraint_error: error / 3.0,
            failure: None,
        }
    }

    fn report() -> SweepReport {
        let wp = vec![
            point("ggl", 0.0, 1e-4, 1e-3, 1e-3),
            point("ggl", 0.0, 1e-6, 1e-5, 2e-3),
            point("ggl", 0.0, 1e-8, 1e-7, 5e-3),
            point("index1", 0.0, 1e-4, 5e-4, 8e-4),
            point("index1", 0.0, 1e-6, 6e-6, 1.5e-3),
            point("index1", 0.0, 1e-8, 8e-8, 3e-3),
        ];
        let stiffness = [1e4, 1e6, 1e8]
            .iter()
            .map(|&k| StiffnessPoint {
                run: point(
                    &format!("decoupled k={k:e}"),
                    k,
                    1e-8,
                    2e2 / k,
                    1e-3 * k.sqrt(),
                ),
                largest_eigenvalue: k.sqrt(),
                sqrt_k_over_m: k.sqrt(),
            })
            .collect();
        SweepReport {
            scene: "test".into(),
            t_end: 1.0,
            reference_source: "GGL rtol 1e-13".into(),
            reference: point("ggl", 0.0, 1e-13, 0.0, 1e-2),
            work_precision: wp,
            stiffness_rtol: 1e-8,
            dae_baseline: point("ggl", 0.0, 1e-8, 1e-7, 5e-3),
            stiffness,
            accuracy: 1e-4,
            sufficient_stiffness: None,
            repeats: 1,
            machine: "test".into(),
        }
    }

    /// `(x, text, fill)` of every `<text>` element of a plotters SVG.
    fn texts(svg: &str) -> Vec<(f64, String, String)> {
        let mut out = Vec::new();
        let mut rest = svg;
        while let Some(i) = rest.find("<text") {
            rest = &rest[i..];
            let x0 = rest.find("x=\"").unwrap() + 3;
            let x: f64 = rest[x0..x0 + rest[x0..].find('"').unwrap()]
                .parse()
                .unwrap();
            let f0 = rest.find("fill=\"").unwrap() + 6;
            let fill = rest[f0..f0 + rest[f0..].find('"').unwrap()].to_string();
            let body = rest.find('>').unwrap() + 1;
            let end = rest.find("</text>").unwrap();
            out.push((x, rest[body..end].trim().to_string(), fill));
            rest = &rest[end..];
        }
        out
    }

    #[test]
    fn work_precision_points_carry_their_tolerance_and_the_legend_is_off_the_data() {
        let path = std::env::temp_dir().join(format!("wp-{}.svg", std::process::id()));
        work_precision_svg(&report(), &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        let t = texts(&svg);
        // each of the 6 points is labelled with its rtol, in its series' colour
        for label in ["1e-4", "1e-6", "1e-8"] {
            for colour in ["#1F77B4", "#FF7F0E"] {
                let n = t
                    .iter()
                    .filter(|(_, s, f)| s == label && f == colour)
                    .count();
                assert_eq!(n, 1, "{label} labels in {colour}: {n}");
            }
        }
        // the legend's names sit right of the 800 px plotting area
        for name in ["ggl", "index1"] {
            let (x, _, _) = t.iter().find(|(_, s, _)| s == name).unwrap();
            assert!(*x > 800.0, "{name} at x = {x}");
        }
        assert!(svg.contains("CPU time per solve, median (s)"));
        assert!(svg.contains("largest error vs reference (m, rad)"));
        let _ = std::fs::remove_file(path);
    }

    #[test]
    fn a_series_whose_points_all_failed_is_left_out_of_the_legend() {
        let mut r = report();
        for w in r.work_precision.iter_mut().filter(|w| w.series == "index1") {
            w.failure = Some("initialisation failed".into());
        }
        let path = std::env::temp_dir().join(format!("wp-failed-{}.svg", std::process::id()));
        work_precision_svg(&r, &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        let t = texts(&svg);
        assert!(t.iter().any(|(_, s, _)| s == "ggl"));
        assert!(!t.iter().any(|(_, s, _)| s == "index1"), "{t:?}");
        let _ = std::fs::remove_file(path);
    }

    #[test]
    fn stiffness_axes_have_units_and_legends_beside_the_panels() {
        let path = std::env::temp_dir().join(format!("st-{}.svg", std::process::id()));
        stiffness_svg(&report(), &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("joint stiffness k (N/m)"));
        assert!(svg.contains("error (m, rad), stretch (m)"));
        let t = texts(&svg);
        for name in ["error vs DAE reference", "CPU time / DAE", "GGL DAE (= 1)"] {
            let (x, _, _) = t.iter().find(|(_, s, _)| s == name).unwrap();
            assert!(*x > 800.0, "{name} at x = {x}");
        }
        let _ = std::fs::remove_file(path);
    }
}
