//! `bondmech animate`, looked at as a person would: headless Chromium opens the SVG or HTML
//! file paused at a time (`#t=T`), takes a screenshot, and the test finds the marker of the
//! traced point (drawn in the first trace colour) and a body's colour in the picture where the
//! CSV that `bondmech run` wrote says they are, mapped through the view the file declares
//! (`data-scale`, `data-origin`, `data-right`, `data-up` on the root `<svg>`).
//!
//! The tests need Chromium (Debian package `chromium`, installed by `.ci/run`); without it they
//! say so and pass locally, and fail under CI (`CI` set).

mod support;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use bondmech::report::animate::TRACE_COLOURS;
use support::cli::{bondmech, scene, tmp};

fn chromium() -> Option<PathBuf> {
    for name in ["chromium", "chromium-browser"] {
        if let Ok(out) = Command::new("which").arg(name).output() {
            if out.status.success() {
                let p = String::from_utf8_lossy(&out.stdout).trim().to_string();
                if !p.is_empty() {
                    return Some(PathBuf::from(p));
                }
            }
        }
    }
    if std::env::var_os("CI").is_some() {
        panic!("chromium is not installed (.ci/run installs it with apt-get)");
    }
    eprintln!("skipped: chromium is not installed (apt-get install chromium)");
    None
}

/// A screenshot of `url` in a `width × height` window, decoded as RGB rows.
struct Picture {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Picture {
    fn at(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.width + x);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Centroid of the pixels within `tol` (Euclidean RGB distance) of `colour`, and their count.
    fn find(&self, colour: (u8, u8, u8), tol: f64) -> Option<([f64; 2], usize)> {
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
        for y in 0..self.height {
            for x in 0..self.width {
                let [r, g, b] = self.at(x, y);
                let d = ((r as f64 - colour.0 as f64).powi(2)
                    + (g as f64 - colour.1 as f64).powi(2)
                    + (b as f64 - colour.2 as f64).powi(2))
                .sqrt();
                if d <= tol {
                    sx += x as f64 + 0.5;
                    sy += y as f64 + 0.5;
                    n += 1;
                }
            }
        }
        (n > 0).then(|| ([sx / n as f64, sy / n as f64], n))
    }
}

fn screenshot(browser: &Path, file: &Path, t: f64, size: (u32, u32), name: &str) -> Picture {
    let png = tmp(name);
    let _ = std::fs::remove_file(&png);
    let profile = tmp(&format!("chromium-profile-{name}"));
    let url = format!("file://{}#t={t}", file.canonicalize().unwrap().display());
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("--window-size={},{}", size.0, size.1))
        .arg(&url)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromium starts");
    // a guard against a browser that never exits, not a timing assertion
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish the screenshot of {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let decoder = png::Decoder::new(std::fs::File::open(&png).expect("screenshot written"));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let rgb = buf[..info.buffer_size()]
        .chunks(channels)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    Picture {
        width: info.width as usize,
        height: info.height as usize,
        rgb,
    }
}

/// The view the animation file declares: world point → pixel.
struct ViewMap {
    scale: f64,
    origin: [f64; 2],
    right: [f64; 3],
    up: [f64; 3],
}

impl ViewMap {
    fn read(file: &Path) -> ViewMap {
        let text = std::fs::read_to_string(file).unwrap();
        let attr = |name: &str| -> Vec<f64> {
            let key = format!("{name}=\"");
            let start = text.find(&key).unwrap_or_else(|| panic!("no {name}")) + key.len();
            let end = start + text[start..].find('"').unwrap();
            text[start..end]
                .split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect()
        };
        let v3 = |v: Vec<f64>| [v[0], v[1], v[2]];
        ViewMap {
            scale: attr("data-scale")[0],
            origin: {
                let o = attr("data-origin");
                [o[0], o[1]]
            },
            right: v3(attr("data-right")),
            up: v3(attr("data-up")),
        }
    }

    fn px(&self, p: [f64; 3]) -> [f64; 2] {
        let d = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        [
            self.origin[0] + self.scale * d(self.right),
            self.origin[1] - self.scale * d(self.up),
        ]
    }
}

/// The CSV that `run` wrote: the value of `column` at time `t` (a row time).
fn csv_value(csv: &Path, column: &str, t: f64) -> f64 {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let c = header.iter().position(|h| *h == column).unwrap();
    for line in lines {
        let cells: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        if (cells[0] - t).abs() < 1e-9 {
            return cells[c];
        }
    }
    panic!("no row at t = {t} in {}", csv.display());
}

fn run_ok(args: &[&str]) -> String {
    let out = bondmech(args);
    assert!(
        out.status.success(),
        "bondmech {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

#[test]
fn double_pendulum_svg_from_the_run_csv_shows_the_bodies_where_the_csv_says() {
    let Some(browser) = chromium() else { return };
    let csv = tmp("anim-dp.csv");
    let svg = tmp("anim-dp.svg");
    run_ok(&[
        "run",
        &scene("double_pendulum.json"),
        "--out",
        csv.to_str().unwrap(),
    ]);
    run_ok(&[
        "animate",
        &scene("double_pendulum.json"),
        "--csv",
        csv.to_str().unwrap(),
        "--fps",
        "50",
        "--out",
        svg.to_str().unwrap(),
    ]);
    let map = ViewMap::read(&svg);
    let mut seen = Vec::new();
    for t in [0.7, 1.9] {
        let pic = screenshot(&browser, &svg, t, (800, 600), &format!("dp-{t}.png"));
        assert_eq!((pic.width, pic.height), (800, 600));
        // the marker of the traced point bar2.A
        let (found, n) = pic
            .find(TRACE_COLOURS[0], 40.0)
            .unwrap_or_else(|| panic!("no marker at t = {t}"));
        assert!(
            n > 60,
            "the marker is a filled circle of radius 6 px ({n} px)"
        );
        let a = [
            csv_value(&csv, "bar2.A.x", t),
            csv_value(&csv, "bar2.A.y", t),
            0.0,
        ];
        let expected = map.px(a);
        assert!(
            distance(found, expected) < 1.5,
            "t = {t}: marker at {found:?}, the CSV's bar2.A maps to {expected:?}"
        );
        // bar2 itself (green) passes through the midpoint of its centre and A
        let mid = [
            0.5 * (csv_value(&csv, "bar2.x", t) + a[0]),
            0.5 * (csv_value(&csv, "bar2.y", t) + a[1]),
            0.0,
        ];
        let [x, y] = map.px(mid);
        let c = pic.at(x as usize, y as usize);
        assert!(
            (c[0] as i32 - 44).abs() < 30
                && (c[1] as i32 - 160).abs() < 30
                && (c[2] as i32 - 44).abs() < 30,
            "t = {t}: pixel {c:?} at bar2's three-quarter point is not bar2's green"
        );
        seen.push(found);
    }
    assert!(distance(seen[0], seen[1]) > 50.0, "the pendulum moved");
}

#[test]
fn html_animation_solves_the_scene_and_seeks_to_the_requested_time() {
    let Some(browser) = chromium() else { return };
    let csv = tmp("anim-html.csv");
    let html = tmp("anim-dp.html");
    // the same solve as `animate` does by itself: the scene's own settings
    run_ok(&[
        "run",
        &scene("double_pendulum.json"),
        "--out",
        csv.to_str().unwrap(),
    ]);
    run_ok(&[
        "animate",
        &scene("double_pendulum.json"),
        "--fps",
        "20",
        "--out",
        html.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&html).unwrap();
    assert!(text.starts_with("<!DOCTYPE html>"));
    for remote in ["src=\"http", "href=\"http", "<link", "@import", "url(http"] {
        assert!(
            !text.contains(remote),
            "nothing is loaded from the network ({remote})"
        );
    }
    let map = ViewMap::read(&html);
    for t in [0.5, 2.25] {
        let pic = screenshot(&browser, &html, t, (800, 700), &format!("dp-html-{t}.png"));
        let (found, _) = pic
            .find(TRACE_COLOURS[0], 40.0)
            .unwrap_or_else(|| panic!("no marker at t = {t}"));
        let expected = map.px([
            csv_value(&csv, "bar2.A.x", t),
            csv_value(&csv, "bar2.A.y", t),
            0.0,
        ]);
        assert!(
            distance(found, expected) < 1.5,
            "t = {t}: marker at {found:?}, the CSV's bar2.A maps to {expected:?}"
        );
    }
}

#[test]
fn spatial_slider_crank_in_the_isometric_view() {
    let Some(browser) = chromium() else { return };
    let csv = tmp("anim-ssc.csv");
    let svg = tmp("anim-ssc.svg");
    run_ok(&[
        "run",
        &scene("spatial_slider_crank.json"),
        "--t-end",
        "1",
        "--out",
        csv.to_str().unwrap(),
    ]);
    let header = std::fs::read_to_string(&csv).unwrap();
    let header = header.lines().next().unwrap();
    assert!(header.contains("crank.qw,crank.qx,crank.qy,crank.qz"));
    run_ok(&[
        "animate",
        &scene("spatial_slider_crank.json"),
        "--csv",
        csv.to_str().unwrap(),
        "--view",
        "iso",
        "--fps",
        "100",
        "--out",
        svg.to_str().unwrap(),
    ]);
    let map = ViewMap::read(&svg);
    let t = 0.3;
    let pic = screenshot(&browser, &svg, t, (800, 600), "ssc.png");
    let (found, _) = pic
        .find(TRACE_COLOURS[0], 40.0)
        .expect("the crank.A marker");
    let expected = map.px([
        csv_value(&csv, "crank.A.x", t),
        csv_value(&csv, "crank.A.y", t),
        csv_value(&csv, "crank.A.z", t),
    ]);
    assert!(
        distance(found, expected) < 1.5,
        "marker at {found:?}, the CSV's crank.A maps to {expected:?}"
    );
}

#[test]
fn animate_refuses_bad_input_with_one_line_naming_it() {
    let csv = tmp("anim-bad.csv");
    std::fs::write(&csv, "time,bar1.x,bar1.y\n0,0.5,0\n1,0.4,-0.1\n").unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["--csv", csv.to_str().unwrap()], "no column `bar1.angle`"),
        (&["--out", "x.gif"], "give a .svg or .html file"),
        (&["--fps", "0"], "--fps: must be > 0"),
        (&["--view", "xz"], "a planar scene has only the xy view"),
        (
            &[
                "--csv",
                csv.to_str().unwrap(),
                "--out",
                csv.to_str().unwrap(),
            ],
            "is an input of this command",
        ),
    ];
    let bad_out = tmp("anim-bad.svg");
    for (extra, message) in cases {
        let dp = scene("double_pendulum.json");
        let mut args = vec!["animate", dp.as_str(), "--t-end", "0.1"];
        if extra.contains(&"--csv") {
            args.truncate(2); // no solve flags with --csv
        }
        args.extend_from_slice(extra);
        if !extra.contains(&"--out") {
            args.extend_from_slice(&["--out", bad_out.to_str().unwrap()]);
        }
        let out = bondmech(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(message), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    // the input was not overwritten
    assert!(std::fs::read_to_string(&csv).unwrap().starts_with("time,"));
}

#[test]
fn another_tools_csv_with_a_time_column_and_quoted_names_animates_the_same() {
    // the run's CSV rewritten as another tool might: `time` first, quoted names, spaces
    let csv = tmp("anim-tool-run.csv");
    run_ok(&[
        "run",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.5",
        "--out",
        csv.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|h| {
            if h == "t" {
                "\"time\"".into()
            } else {
                format!(" \"{h}\"")
            }
        })
        .collect();
    let mut other = format!("# written by another tool\n{}\n", header.join(","));
    for l in lines {
        other.push_str(&l.replace(',', ", "));
        other.push('\n');
    }
    let tool = tmp("anim-tool-other.csv");
    std::fs::write(&tool, other).unwrap();
    let (a, b) = (tmp("anim-tool-a.svg"), tmp("anim-tool-b.svg"));
    for (input, out) in [(&csv, &a), (&tool, &b)] {
        run_ok(&[
            "animate",
            &scene("double_pendulum.json"),
            "--csv",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
    }
    let (a, b) = (
        std::fs::read_to_string(a).unwrap(),
        std::fs::read_to_string(b).unwrap(),
    );
    assert!(a.contains("<animateTransform "), "the motion is animated");
    assert_eq!(a, b, "the same motion read from either table");
}

#[test]
fn spatial_attitude_from_cardan_columns_draws_what_the_quaternion_draws() {
    // the same run without its quaternion columns: the Cardan angles give the same picture
    let csv = tmp("anim-cardan-q.csv");
    run_ok(&[
        "run",
        &scene("spatial_slider_crank.json"),
        "--t-end",
        "0.5",
        "--out",
        csv.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
    let keep: Vec<usize> = (0..rows[0].len())
        .filter(|&c| {
            !matches!(
                rows[0][c].rsplit('.').next(),
                Some("qw" | "qx" | "qy" | "qz")
            )
        })
        .collect();
    assert!(
        keep.len() < rows[0].len(),
        "the run wrote quaternion columns"
    );
    let cardan: String = rows
        .iter()
        .map(|r| keep.iter().map(|&c| r[c]).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    let csv_cardan = tmp("anim-cardan-e.csv");
    std::fs::write(&csv_cardan, cardan).unwrap();
    let numbers = |input: &Path, out: &str| -> Vec<f64> {
        let out = tmp(out);
        run_ok(&[
            "animate",
            &scene("spatial_slider_crank.json"),
            "--csv",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        // the traces of crank.A and slider.C: every row's pose, through the attitude columns
        let svg = std::fs::read_to_string(out).unwrap();
        svg.lines()
            .filter(|l| l.starts_with("<polyline points=\""))
            .flat_map(|l| {
                let l = &l["<polyline points=\"".len()..];
                l[..l.find('"').unwrap()]
                    .split([' ', ','])
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let (q, e) = (
        numbers(&csv, "anim-cardan-q.svg"),
        numbers(&csv_cardan, "anim-cardan-e.svg"),
    );
    assert_eq!(q.len(), e.len());
    assert!(q.len() > 200, "two traces of 51 rows");
    let worst = q
        .iter()
        .zip(&e)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 0.1 + 1e-9, "pixel coordinates differ by {worst}");
}

#[test]
fn animate_refuses_a_raw_bond_graph_scene() {
    let out = bondmech(&[
        "animate",
        &scene("bg_mass_spring_damper.json"),
        "--out",
        tmp("anim-bg.svg").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("animate needs a scene with bodies"), "{err}");
}

/// Loads `file` in headless Chromium with its console logged; returns the console lines and
/// the DOM after the scripts ran.
fn console_and_dom(browser: &Path, file: &Path, name: &str) -> (Vec<String>, String) {
    let profile = tmp(&format!("chromium-profile-console-{name}"));
    let url = format!("file://{}#t=0.01", file.canonicalize().unwrap().display());
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=3000",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(&url)
        .output()
        .expect("chromium starts");
    let console = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.contains("CONSOLE"))
        .map(str::to_string)
        .collect();
    (console, String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn every_bundled_scene_animates_without_a_console_error() {
    let Some(browser) = chromium() else { return };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json") && !n.starts_with("bg_"))
        .collect();
    names.sort();
    assert!(names.len() >= 10, "{names:?}");
    let mut failures = Vec::new();
    for name in &names {
        for ext in ["html", "svg"] {
            let stem = name.trim_end_matches(".json");
            let file = tmp(&format!("console-{stem}.{ext}"));
            run_ok(&["animate", &scene(name), "--out", file.to_str().unwrap()]);
            let text = std::fs::read_to_string(&file).unwrap();
            for remote in ["src=\"http", "href=\"http", "<link", "@import", "url(http"] {
                assert!(!text.contains(remote), "{stem}.{ext} loads {remote}");
            }
            let (console, dom) = console_and_dom(&browser, &file, &format!("{stem}-{ext}"));
            let errors: Vec<&String> = console
                .iter()
                .filter(|l| l.contains("ERROR") || l.contains("Uncaught") || l.contains("WARNING"))
                .collect();
            if !errors.is_empty() {
                failures.push(format!("{stem}.{ext}: {errors:?}"));
            }
            // the page's script ran: the clock shows the time the page was opened at
            let clock = dom
                .find("id=\"clock\"")
                .map(|i| &dom[i..(i + 200).min(dom.len())])
                .unwrap_or("no clock");
            assert!(
                clock.contains("t = 0.01"),
                "{stem}.{ext}: the clock does not show t = 0.01: {clock} ({} console lines)",
                console.len()
            );
        }
    }
    assert!(failures.is_empty(), "console errors: {failures:#?}");
}

/// The 3D page of a spatial scene (`animate --out FILE.html`): the renderer it inlines (the one
/// the playground serves as `/view3d.js`) draws the bodies and moves the traced point with the
/// clock; a body named with `</script>` in it is data, not the end of the page's data block.
#[test]
fn spatial_html_page_draws_the_3d_view_and_follows_the_clock() {
    let Some(browser) = chromium() else { return };
    let mut doc: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(scene("hinged_double_pendulum_3d.json")).unwrap(),
    )
    .unwrap();
    let evil = "bar2</script><b id=x>no</b>";
    doc["bodies"][1]["name"] = evil.into();
    doc["joints"][1]["bodies"][1] = evil.into();
    doc["outputs"] = serde_json::json!([format!("{evil}.A")]);
    doc["solve"]["t_end"] = 1.0.into();
    let path = tmp("anim-3d-evil.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    let html = tmp("anim-3d.html");
    run_ok(&[
        "animate",
        path.to_str().unwrap(),
        "--out",
        html.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&html).unwrap();
    assert_eq!(
        text.matches("</script>").count(),
        2,
        "the data block and the script end once each"
    );
    let marker = TRACE_COLOURS[0];
    let mut seen = Vec::new();
    for t in [0.0, 0.6] {
        let pic = screenshot(&browser, &html, t, (800, 600), &format!("3d-html-{t}.png"));
        let (at, n) = pic
            .find(marker, 40.0)
            .unwrap_or_else(|| panic!("t = {t}: the traced point's marker is not drawn"));
        assert!(n > 20, "t = {t}: a marker of {n} pixels");
        seen.push(at);
    }
    // the bar falls from horizontal: its tip moves down the picture by a good part of its length
    assert!(
        seen[1][1] - seen[0][1] > 50.0,
        "the traced point moves down with the clock: {seen:?}"
    );
}
