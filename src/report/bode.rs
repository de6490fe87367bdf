//! The Bode plot of a linear model (`bondmech linearize --bode OUT.svg`): magnitude
//! `20 log₁₀ |H(iω)|` (dB) and phase `arg H(iω)` (degrees, unwrapped along the frequency) of
//! every input → output pair of `H(iω) = C (iω I − A)⁻¹ B + D`, against the frequency
//! `f = ω / 2π` (Hz, log axis) over a decade either side of the modes, with each
//! oscillating mode's natural frequency marked. The axes, ticks and legend follow the plot
//! rules of `plot` ([`super::timeplot`], [`super::plot`]): the legend beside the panels, every
//! axis with its unit.

use std::path::Path;

use plotters::prelude::*;

use super::error::{ReportError, Result};
use super::plot::{draw_legend, plot_error, LegendEntry, LEGEND_WIDTH};
use super::timeplot::{range, series_colour, tick_label};
use crate::analysis::linear_model::LinearModel;

/// Frequencies sampled per decade.
const PER_DECADE: usize = 200;

/// The frequency range (Hz) of the plot: a decade below the lowest and above the highest
/// non-zero natural frequency, whole decades; `[0.01, 100]` without one.
pub fn frequency_range(lm: &LinearModel) -> (f64, f64) {
    let f: Vec<f64> = lm
        .modes
        .iter()
        .map(|m| m.frequency_hz)
        .filter(|f| *f > 0.0 && f.is_finite())
        .collect();
    if f.is_empty() {
        return (0.01, 100.0);
    }
    let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = f.iter().copied().fold(0.0, f64::max);
    (
        10f64.powf(lo.log10().floor() - 1.0),
        10f64.powf(hi.log10().ceil() + 1.0),
    )
}

/// The sampled response of pair `(output, input)`: `(f, dB, degrees)`, the phase unwrapped.
fn response(lm: &LinearModel, freqs: &[f64]) -> Vec<Vec<(f64, f64, f64)>> {
    let (ny, nu) = (lm.c.nrows(), lm.b.ncols());
    let mut out = vec![Vec::with_capacity(freqs.len()); ny * nu];
    for &f in freqs {
        let Some(h) = lm.frequency_response(2.0 * std::f64::consts::PI * f) else {
            continue;
        };
        for i in 0..ny {
            for k in 0..nu {
                let z = h[(i, k)];
                let series: &mut Vec<(f64, f64, f64)> = &mut out[i * nu + k];
                let mut deg = z.arg().to_degrees();
                if let Some(&(_, _, prev)) = series.last() {
                    deg += 360.0 * ((prev - deg) / 360.0).round();
                }
                let db = 20.0 * z.norm().log10();
                if db.is_finite() && deg.is_finite() {
                    series.push((f, db, deg));
                }
            }
        }
    }
    out
}

/// A frequency tick: `0.01`, `1`, `100` (decades as plain numbers, small and large as `1e-4`).
fn frequency_label(f: f64) -> String {
    if (1e-3..1e4).contains(&f) {
        let s = format!("{f:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{f:.0e}")
    }
}

/// Draws the Bode plot of `lm` (titled with `name`) to the SVG `path`. Refused when the model
/// has no inputs or no outputs (nothing to draw).
pub fn bode_svg(lm: &LinearModel, name: &str, path: &Path) -> Result<()> {
    let err = |e| plot_error(path, e);
    if lm.b.ncols() == 0 || lm.c.nrows() == 0 {
        return Err(ReportError::Io {
            path: path.display().to_string(),
            source: std::io::Error::other(
                "--bode: the scene declares no inputs, so there is no frequency response to draw (add \"inputs\" used in a load, §22)",
            ),
        });
    }
    let (f0, f1) = frequency_range(lm);
    let decades = (f1 / f0).log10();
    let n = (decades * PER_DECADE as f64).ceil() as usize;
    let mut freqs: Vec<f64> = (0..=n)
        .map(|k| f0 * 10f64.powf(decades * k as f64 / n as f64))
        .collect();
    // each resonance sampled finely, so a light damping's peak is drawn at its height
    let resonances: Vec<(usize, f64)> = lm
        .modes
        .iter()
        .enumerate()
        .filter(|(_, m)| m.eigenvalue.1 > 0.0)
        .map(|(k, m)| (k + 1, m.eigenvalue.1 / (2.0 * std::f64::consts::PI)))
        .collect();
    for &(_, fr) in &resonances {
        for k in -50..=50 {
            freqs.push(fr * (1.0 + 1e-3 * k as f64));
        }
    }
    freqs.retain(|f| (f0..=f1).contains(f));
    freqs.sort_by(f64::total_cmp);
    let series = response(lm, &freqs);
    let names: Vec<String> = (0..lm.c.nrows())
        .flat_map(|i| (0..lm.b.ncols()).map(move |k| (i, k)))
        .map(|(i, k)| format!("{} → {}", lm.inputs[k], lm.outputs[i]))
        .collect();
    let (m0, m1) = range(series.iter().flatten().map(|p| p.1), false);
    let (p0, p1) = range(series.iter().flatten().map(|p| p.2), false);

    // drawn into memory, then written beside the target and renamed into place: a failed
    // write never leaves a cut drawing where a previous one was
    let mut text = String::new();
    {
        let root =
            SVGBackend::with_string(&mut text, (800 + LEGEND_WIDTH, 720)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (plots, legend_area) = root.split_horizontally(800);
        let plots = plots
            .titled(
                &format!("{name}: frequency response at {}", lm.at),
                ("sans-serif", 20),
            )
            .map_err(err)?;
        let (top, bottom) = plots.split_vertically(340);
        let colour = |i: usize| series_colour(i).stroke_width(2);
        for (area, (y0, y1), desc, pick) in [
            (&top, (m0, m1), "magnitude (dB)", 1usize),
            (&bottom, (p0, p1), "phase (deg)", 2usize),
        ] {
            let mut chart = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(70)
                .build_cartesian_2d((f0..f1).log_scale(), y0..y1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("frequency f (Hz)")
                .y_desc(desc)
                .label_style(("sans-serif", 13))
                .axis_desc_style(("sans-serif", 15))
                .light_line_style(RGBColor(245, 245, 245))
                .x_label_formatter(&|v| frequency_label(*v))
                .y_label_formatter(&|v| tick_label(*v, y0, y1))
                .draw()
                .map_err(err)?;
            for (i, s) in series.iter().enumerate() {
                let pts = s.iter().map(|p| (p.0, if pick == 1 { p.1 } else { p.2 }));
                chart
                    .draw_series(LineSeries::new(pts, colour(i)))
                    .map_err(err)?;
            }
            // the resonances: a dashed line at each oscillating mode's natural frequency
            for &(k, fr) in &resonances {
                let grey = RGBColor(110, 110, 110);
                let steps = 24;
                for s in 0..steps {
                    if s % 2 == 1 {
                        continue;
                    }
                    let a = y0 + (y1 - y0) * s as f64 / steps as f64;
                    let b = y0 + (y1 - y0) * (s + 1) as f64 / steps as f64;
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![(fr, a), (fr, b)],
                            grey.stroke_width(1),
                        )))
                        .map_err(err)?;
                }
                if pick == 1 {
                    chart
                        .plotting_area()
                        .draw(
                            &(EmptyElement::at((fr, y1))
                                + Text::new(
                                    format!("mode {k}"),
                                    (4, 4 + 14 * ((k as i32 - 1) % 3)),
                                    ("sans-serif", 12).into_font().color(&grey),
                                )),
                        )
                        .map_err(err)?;
                }
            }
        }
        let legend: Vec<LegendEntry> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.clone(), colour(i)))
            .collect();
        legend_area
            .draw(&Text::new(
                "input → output",
                (8, 40),
                ("sans-serif", 13).into_font().color(&BLACK),
            ))
            .map_err(err)?;
        draw_legend(&legend_area, &legend, 72).map_err(err)?;
        let notes: Vec<String> = lm
            .modes
            .iter()
            .enumerate()
            .map(|(k, m)| {
                format!(
                    "mode {}: {:.4} Hz, ζ {}",
                    k + 1,
                    m.frequency_hz,
                    m.damping_ratio
                        .map_or_else(|| "-".to_string(), |z| format!("{z:.3}"))
                )
            })
            .collect();
        for (i, t) in notes.iter().enumerate() {
            legend_area
                .draw(&Text::new(
                    t.clone(),
                    (8, 100 + 20 * (legend.len() as i32 + i as i32)),
                    ("sans-serif", 13).into_font().color(&BLACK),
                ))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    crate::output::write_atomic(path, text.as_bytes()).map_err(|source| ReportError::Io {
        path: path.display().to_string(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequency_ticks_read_as_plain_numbers() {
        assert_eq!(frequency_label(0.01), "0.01");
        assert_eq!(frequency_label(1.0), "1");
        assert_eq!(frequency_label(100.0), "100");
        assert_eq!(frequency_label(1e-5), "1e-5");
    }
}
