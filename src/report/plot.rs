//! SVG plots of a [`SweepReport`] (with `plotters`): error against CPU time (log-log, one line
//! per formulation) and error, constraint violation and cost against the joint stiffness `k`.

use std::path::Path;

use plotters::prelude::*;

use super::sweep::{SweepReport, WorkPoint};
use crate::{Error, Result};

const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

fn plot_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Io {
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

fn usable(w: &WorkPoint) -> bool {
    w.failure.is_none() && w.error.is_finite() && w.error > 0.0 && w.cpu_seconds > 0.0
}

/// Error against CPU time, log-log, one line per series.
pub fn work_precision_svg(report: &SweepReport, path: &Path) -> Result<()> {
    let err = |e| plot_error(path, e);
    let mut series: Vec<&str> = Vec::new();
    for w in &report.work_precision {
        if !series.contains(&w.series.as_str()) {
            series.push(&w.series);
        }
    }
    let pts: Vec<&WorkPoint> = report.work_precision.iter().filter(|w| usable(w)).collect();
    let (x0, x1) = log_range(pts.iter().map(|w| w.cpu_seconds));
    let (y0, y1) = log_range(pts.iter().map(|w| w.error));
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: work-precision (t_end = {} s)",
                report.scene, report.t_end
            ),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("CPU time per solve (s, median)")
        .y_desc("max error vs reference")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let mut line: Vec<(f64, f64)> = pts
            .iter()
            .filter(|w| w.series == *s)
            .map(|w| (w.cpu_seconds, w.error))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(err)?
            .label(*s)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
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
    let root = SVGBackend::new(path, (800, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (top, bottom) = root.split_vertically(400);
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
        .y_desc("error / stretch")
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
    for (label, colour, line) in lines {
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
    }
    let acc = report.accuracy;
    chart
        .draw_series(LineSeries::new(
            vec![(k0, acc), (k1, acc)],
            COLOURS[3].stroke_width(1),
        ))
        .map_err(err)?
        .label("requested accuracy")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], COLOURS[3]));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;

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
        .y_desc("cost relative to the GGL DAE")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .draw()
        .map_err(err)?;
    for (label, colour, line) in [
        ("CPU time / DAE", COLOURS[2], cpu),
        ("steps / DAE", COLOURS[4], steps),
    ] {
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
    }
    chart
        .draw_series(LineSeries::new(
            vec![(k0, 1.0), (k1, 1.0)],
            BLACK.stroke_width(1),
        ))
        .map_err(err)?
        .label("GGL DAE")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
