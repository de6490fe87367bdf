//! `bondmech plot RUN.csv` and `bondmech run --plot DIR`: one SVG per unit group, units on the
//! axes, the legend beside the data, and the data drawn where the CSV puts it.

mod support;

use support::cli::{bondmech, scene, tmp};

/// The `points` of the polylines drawn in `colour` with stroke width 2 (the data series).
fn series(svg: &str, colour: &str) -> Vec<Vec<(f64, f64)>> {
    svg.lines()
        .filter(|l| {
            l.starts_with("<polyline")
                && l.contains(&format!("stroke=\"{colour}\""))
                && l.contains("stroke-width=\"2\"")
        })
        .map(|l| {
            let start = l.find("points=\"").unwrap() + 8;
            let end = start + l[start..].find('"').unwrap();
            l[start..end]
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}

#[test]
fn plot_reads_another_tools_csv_and_draws_each_group_with_its_unit() {
    let dir = tmp("plots-hand");
    let csv = tmp("plot-hand.csv");
    // written by hand: a.x = 2t (a straight line), a.angle = t², constant energy
    let mut text = String::from("\"time\",\"a.x\",\"a.angle\",\"energy\",\"constraint_error\"\n");
    for k in 0..=20 {
        let t = k as f64 * 0.05;
        text.push_str(&format!(
            "{t},{},{},-4.5,{}\n",
            2.0 * t,
            t * t,
            1e-12 * (1.0 + t)
        ));
    }
    std::fs::write(&csv, &text).unwrap();
    let out = bondmech(&[
        "plot",
        csv.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    for (file, axis, legend) in [
        ("positions.svg", "position (m)", "a.x"),
        ("angles.svg", "angle (rad)", "a.angle"),
        ("energy.svg", "energy (J)", "energy"),
        (
            "constraint_error.svg",
            "largest |g(q)| (m, rad)",
            "constraint_error",
        ),
    ] {
        let svg = read(file);
        assert!(svg.contains(axis), "{file}: no axis label {axis}");
        assert!(svg.contains("time t (s)"), "{file}: no time axis");
        assert!(
            svg.contains(&format!("\n{legend}\n")),
            "{file}: no legend {legend}"
        );
    }
    assert!(
        !dir.join("velocities.svg").exists(),
        "no velocity column, no file"
    );
    // a.x = 2t is a straight line through all 21 samples, rising to the right (y down)
    let pos = read("positions.svg");
    let lines = series(&pos, "#1F77B4");
    let line = lines
        .iter()
        .find(|l| l.len() == 21)
        .expect("21 points of a.x");
    let (a, b) = (line[0], line[20]);
    assert!(b.0 - a.0 > 500.0 && a.1 - b.1 > 300.0, "{a:?} → {b:?}");
    for (k, p) in line.iter().enumerate() {
        let s = k as f64 / 20.0;
        let on_line = (a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1));
        assert!(
            (p.0 - on_line.0).abs() <= 1.0 && (p.1 - on_line.1).abs() <= 1.0,
            "sample {k} at {p:?}, the line passes {on_line:?}"
        );
    }
    // the legend sits right of the plotting area, off the data
    let legend_x: f64 = {
        let i = pos.find("\na.x\n").unwrap();
        let tag = pos[..i].rfind("<text").unwrap();
        let x = &pos[tag..i];
        let s = x.find("x=\"").unwrap() + 3;
        x[s..s + x[s..].find('"').unwrap()].parse().unwrap()
    };
    assert!(
        legend_x > b.0,
        "legend at x = {legend_x}, data up to {}",
        b.0
    );
}

#[test]
fn run_plot_writes_the_groups_of_the_standard_columns() {
    let dir = tmp("plots-run");
    let out = bondmech(&[
        "run",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.2",
        "--table",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (file, unit) in [
        ("positions.svg", "(m)"),
        ("angles.svg", "(rad)"),
        ("velocities.svg", "(m/s)"),
        ("angular_velocities.svg", "(rad/s)"),
        ("energy.svg", "(J)"),
        ("constraint_error.svg", "(m, rad)"),
    ] {
        let svg = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(svg.contains(unit), "{file} has no unit {unit}");
    }
}

#[test]
fn plot_refuses_a_table_without_time_naming_file_and_line() {
    let csv = tmp("plot-bad.csv");
    std::fs::write(&csv, "x,y\n0,1\n").unwrap();
    let out = bondmech(&[
        "plot",
        csv.to_str().unwrap(),
        "--out",
        tmp("p").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("plot-bad.csv line 1"), "{err}");
    assert!(err.contains("`t` or `time`"), "{err}");
}
