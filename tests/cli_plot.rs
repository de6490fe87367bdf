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

/// The texts of a plotters SVG: `(x, text-anchor, text)`.
fn texts(svg: &str) -> Vec<(f64, String, String)> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find("<text") {
        rest = &rest[i..];
        let head_end = rest.find('>').unwrap();
        let head = &rest[..head_end];
        let attr = |name: &str| -> String {
            let key = format!("{name}=\"");
            head.find(&key)
                .map(|s| {
                    let s = s + key.len();
                    head[s..s + head[s..].find('"').unwrap()].to_string()
                })
                .unwrap_or_default()
        };
        let end = rest.find("</text>").unwrap();
        out.push((
            attr("x").parse().unwrap_or(f64::NAN),
            attr("text-anchor"),
            rest[head_end + 1..end].trim().to_string(),
        ));
        rest = &rest[end..];
    }
    out
}

#[test]
fn energy_ticks_resolve_the_drift_and_columns_pick_curves() {
    let dir = tmp("plots-energy");
    let csv = tmp("plots-energy.csv");
    let out = bondmech(&[
        "run",
        &scene("double_pendulum.json"),
        "--out",
        csv.to_str().unwrap(),
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let svg = std::fs::read_to_string(dir.join("energy.svg")).unwrap();
    let t = texts(&svg);
    // y tick labels: right-aligned numbers left of the plotting area
    let ticks: std::collections::BTreeSet<String> = t
        .iter()
        .filter(|(x, anchor, s)| *x < 100.0 && anchor == "end" && s.parse::<f64>().is_ok())
        .map(|(_, _, s)| s.clone())
        .collect();
    assert!(
        ticks.len() >= 3,
        "the energy axis has {} distinct tick labels: {ticks:?}",
        ticks.len()
    );
    // the scene's name is the title
    assert!(
        t.iter()
            .any(|(_, _, s)| s.starts_with("double_pendulum: energy")),
        "{t:?}"
    );
    // --columns: only the picked curves, and a wrong name is refused with the column named
    let dir2 = tmp("plots-columns");
    let out = bondmech(&[
        "plot",
        csv.to_str().unwrap(),
        "--out",
        dir2.to_str().unwrap(),
        "--columns",
        "bar2.*,energy",
        "--title",
        "picked",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pos = std::fs::read_to_string(dir2.join("positions.svg")).unwrap();
    let legend: Vec<String> = texts(&pos)
        .into_iter()
        .filter(|(x, _, _)| *x > 760.0)
        .map(|(_, _, s)| s)
        .collect();
    assert!(legend.iter().any(|s| s == "bar2.x"), "{legend:?}");
    assert!(!legend.iter().any(|s| s.starts_with("bar1")), "{legend:?}");
    assert!(pos.contains("picked: positions"));
    assert!(!dir2.join("constraint_error.svg").exists(), "not picked");
    let out = bondmech(&[
        "plot",
        csv.to_str().unwrap(),
        "--out",
        dir2.to_str().unwrap(),
        "--columns",
        "bar9.x",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no column `bar9.x`"));
}

#[test]
fn run_plot_writes_no_csv_to_the_terminal_unless_asked() {
    let dir = tmp("plots-quiet");
    let args = [
        "run",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.2",
        "--plot",
        dir.to_str().unwrap(),
    ];
    let out = bondmech(&args);
    assert!(out.status.success());
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(dir.join("positions.svg").exists());
    let mut asked = args.to_vec();
    asked.extend(["--out", "-"]);
    let out = bondmech(&asked);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("t,"));
}

#[test]
fn many_curves_do_not_share_a_colour() {
    let dir = tmp("plots-bricard");
    let out = bondmech(&[
        "run",
        &scene("bricard.json"),
        "--t-end",
        "0.2",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let svg = std::fs::read_to_string(dir.join("positions.svg")).unwrap();
    let colours: Vec<&str> = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke-width=\"2\""))
        .filter_map(|l| {
            let s = l.find("stroke=\"")? + 8;
            Some(&l[s..s + l[s..].find('"')?])
        })
        .collect();
    let distinct: std::collections::BTreeSet<&str> = colours.iter().copied().collect();
    // every data curve and its legend sample: each colour twice at most
    assert!(colours.len() >= 30, "{} curves", colours.len());
    assert_eq!(distinct.len() * 2, colours.len(), "{colours:?}");
}
