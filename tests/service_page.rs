//! The routes the playground needs (issue 37), checked without a browser against references
//! independent of the service: the `scenes/` directory as it is on disk, the command line's
//! error lines, `bondmech animate`'s own SVG and frames, and the page's test contract (its ids).
//! The page itself in a browser: `tests/playground.rs`.

mod service_support;

use std::io::Write;

use bondmech::service::Config;
use service_support::*;

fn tmp_scene(text: &str, tag: &str) -> std::path::PathBuf {
    let file =
        std::env::temp_dir().join(format!("bondmech-page-{tag}-{}.json", std::process::id()));
    std::fs::File::create(&file)
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    file
}

#[test]
fn scenes_are_the_bundled_files_by_name() {
    let server = start(Config::default());
    let r = get(server.addr(), "/v1/scenes");
    assert_eq!(r.status, 200);
    assert_eq!(r.header("content-type"), Some("application/json"));
    let names: Vec<String> = serde_json::from_value(r.json()).unwrap();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|n| n.strip_suffix(".json").map(str::to_string))
        .collect();
    files.sort();
    assert_eq!(names, files);
    assert!(names.len() >= 20, "{names:?}");
    for n in &names {
        let r = get(server.addr(), &format!("/v1/scenes/{n}"));
        assert_eq!(r.status, 200, "{n}");
        assert_eq!(r.text(), scene_text(&format!("{n}.json")), "{n}");
    }
    let p = get(server.addr(), "/v1/scenes/no_such_scene").problem(404);
    let detail = p["detail"].as_str().unwrap();
    assert!(
        detail.contains("no_such_scene") && detail.contains("double_pendulum"),
        "{p}"
    );
    // a path that tries to leave the list is just an unknown name
    get(server.addr(), "/v1/scenes/..%2FCargo.toml").problem(404);
    server.shutdown().unwrap();
}

#[test]
fn validate_gives_the_clis_problems_and_always_200() {
    let server = start(Config::default());
    let scene = r#"{"dimension": 2,
      "bodies": [{"name": "a", "mass": -1, "inertia": 1},
                 {"name": "b", "mass": 1, "inertia": -2}],
      "joints": [{"type": "revolute", "bodies": ["ground", "nobody"], "points": [[0, 0], "O"]}],
      "solve": {"t_end": 1, "rtol": 0}}"#;
    let file = tmp_scene(scene, "validate");
    let (ok, _, stderr) = cli(&["run", file.to_str().unwrap()]);
    std::fs::remove_file(&file).ok();
    assert!(!ok);
    let r = post(server.addr(), "/v1/validate", scene.as_bytes());
    assert_eq!(r.status, 200);
    let v = r.json();
    assert_eq!(v["valid"], false);
    let lines: Vec<String> = v["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            format!(
                "{}: {}",
                e["path"].as_str().unwrap(),
                e["message"].as_str().unwrap()
            )
        })
        .collect();
    assert_eq!(format!("bondmech: {}", lines.join("; ")), stderr.trim_end());
    assert!(lines.iter().any(|l| l.starts_with("bodies[0].mass: ")));
    // valid
    let v = post(
        server.addr(),
        "/v1/validate",
        scene_text("double_pendulum.json").as_bytes(),
    );
    assert_eq!(v.status, 200);
    assert_eq!(v.json(), serde_json::json!({"valid": true, "errors": []}));
    // malformed JSON: line and column, as /v1/run's 400 gives them
    let bad = b"{\n  \"dimension\": 2,\n  \"bodies\": [\n";
    let v = post(server.addr(), "/v1/validate", bad).json();
    let p = post(server.addr(), "/v1/run", bad).problem(400);
    assert_eq!(v["valid"], false);
    assert_eq!(v["line"], p["line"]);
    assert_eq!(v["column"], p["column"]);
    assert_eq!(v["errors"][0]["message"], p["detail"]);
    server.shutdown().unwrap();
}

#[test]
fn animate_is_the_clis_animation() {
    let server = start(Config::default());
    for (scene, query, flags) in [
        ("double_pendulum.json", "", vec![]),
        (
            "hinged_double_pendulum_3d.json",
            "?t_end=0.5&rtol=1e-7",
            vec!["--t-end", "0.5", "--rtol", "1e-7"],
        ),
    ] {
        let text = scene_text(scene);
        let r = post(
            server.addr(),
            &format!("/v1/animate{query}"),
            text.as_bytes(),
        );
        assert_eq!(r.status, 200, "{}", r.text());
        assert_eq!(r.header("content-type"), Some("image/svg+xml"));
        let dir = std::env::temp_dir().join(format!(
            "bondmech-page-animate-{}-{scene}",
            std::process::id()
        ));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("a.svg");
        let frames = dir.join("f.json");
        let path = scene_path(scene);
        let mut args = vec![
            "animate",
            path.as_str(),
            "--out",
            out.to_str().unwrap(),
            "--frames",
            frames.to_str().unwrap(),
        ];
        args.extend(flags.iter().copied());
        let (ok, _, err) = cli(&args);
        assert!(ok, "{err}");
        assert_eq!(
            r.text(),
            std::fs::read_to_string(&out).unwrap(),
            "{scene}: the service's SVG is the command line's"
        );
        let sep = if query.is_empty() { "?" } else { "&" };
        let f = post(
            server.addr(),
            &format!("/v1/animate{query}{sep}format=frames"),
            text.as_bytes(),
        );
        assert_eq!(f.status, 200, "{}", f.text());
        assert_eq!(
            f.text(),
            std::fs::read_to_string(&frames).unwrap(),
            "{scene}: frames"
        );
        if scene.ends_with("_3d.json") {
            // the 3D view's data is what the command line's 3D page draws
            let html = dir.join("a.html");
            let mut args = vec!["animate", path.as_str(), "--out", html.to_str().unwrap()];
            args.extend(flags.iter().copied());
            let (ok, _, err) = cli(&args);
            assert!(ok, "{err}");
            let page = std::fs::read_to_string(&html).unwrap();
            let open = "<script id=\"scene-data\" type=\"application/json\">";
            let start = page.find(open).expect("the page's data block") + open.len();
            let len = page[start..].find("</script>").unwrap();
            let cli_data: serde_json::Value =
                serde_json::from_str(&page[start..start + len]).unwrap();
            let v = post(
                server.addr(),
                &format!("/v1/animate{query}{sep}format=view3d"),
                text.as_bytes(),
            );
            assert_eq!(v.status, 200, "{}", v.text());
            assert_eq!(v.header("content-type"), Some("application/json"));
            assert_eq!(v.json(), cli_data, "{scene}: the 3D view's data");
            let bodies = cli_data["bodies"].as_array().unwrap().len();
            assert!(bodies > 0);
            for pose in cli_data["poses"].as_array().unwrap() {
                assert_eq!(pose.as_array().unwrap().len(), 7 * bodies);
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }
    // a raw bond graph has nothing to draw; a bad view is named
    let p = post(
        server.addr(),
        "/v1/animate",
        scene_text("bg_dc_motor.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["errors"][0]["path"], "bond_graph", "{p}");
    let p = post(
        server.addr(),
        "/v1/animate?view=top",
        scene_text("pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["parameter"], "view", "{p}");
    // a planar scene has no 3D view: the parameter is named, nothing is solved
    let p = post(
        server.addr(),
        "/v1/animate?format=view3d",
        scene_text("pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["parameter"], "format", "{p}");
    assert!(p["detail"].as_str().unwrap().contains("spatial"), "{p}");
    server.shutdown().unwrap();
}

#[test]
fn the_page_keeps_its_ids_and_allows_only_its_origin() {
    let server = start(Config::default());
    let r = get(server.addr(), "/");
    assert_eq!(r.status, 200);
    assert_eq!(r.header("content-type"), Some("text/html; charset=utf-8"));
    let csp = r.header("content-security-policy").unwrap().to_string();
    assert!(csp.contains("default-src 'none'") && csp.contains("script-src 'self'"));
    assert!(!csp.contains("http") && !csp.contains("unsafe"), "{csp}");
    let html = r.text();
    for id in [
        "scene-picker",
        "editor",
        "problems",
        "run",
        "compare",
        "summary",
        "plot",
        "animation",
        "time",
        "play",
        "graph",
        "csv",
        "verdict",
        "formulation",
        "rtol",
        "t_end",
        "cancel",
        "progress",
        // the workbench (issue 50)
        "equilibrium",
        "linearize",
        "equilibrium-result",
        "modes",
        "bode",
        "plot-search",
        "plot-columns",
        "plot-reset",
        "editor-gutter",
        "fullscreen",
        "graph-collapse",
    ] {
        assert_eq!(
            html.matches(&format!("id=\"{id}\"")).count(),
            1,
            "#{id} once on the page"
        );
    }
    assert!(html.contains("<input id=\"time\" type=\"range\""));
    // no inline script, nothing from elsewhere
    assert_eq!(html.matches("<script").count(), 2);
    assert!(html.contains("<script src=\"/playground.js\""));
    assert!(html.contains("<script src=\"/view3d.js\""));
    assert!(!html.contains("http://") && !html.contains("https://") && !html.contains("//cdn"));
    for (path, ctype) in [
        ("/playground.js", "text/javascript; charset=utf-8"),
        ("/playground.css", "text/css; charset=utf-8"),
        ("/view3d.js", "text/javascript; charset=utf-8"),
    ] {
        let r = get(server.addr(), path);
        assert_eq!(r.status, 200, "{path}");
        assert_eq!(r.header("content-type"), Some(ctype), "{path}");
        assert_eq!(r.header("x-content-type-options"), Some("nosniff"));
        // the SVG namespace is a name, not an address
        let t = r.text().replace("http://www.w3.org/2000/svg", "");
        assert!(
            !t.contains("http://") && !t.contains("https://"),
            "{path} names no other origin"
        );
    }
    // the JavaScript inserts text from scenes as text only
    let js = get(server.addr(), "/playground.js").text() + &get(server.addr(), "/view3d.js").text();
    for sink in [
        "innerHTML",
        "outerHTML",
        "insertAdjacentHTML",
        "document.write",
        "eval(",
    ] {
        assert!(!js.contains(sink), "playground.js uses {sink}");
    }
    // the new routes are in the OpenAPI document
    let o = get(server.addr(), "/openapi.json").json();
    for (path, method) in [
        ("/v1/scenes", "get"),
        ("/v1/scenes/{name}", "get"),
        ("/v1/validate", "post"),
        ("/v1/animate", "post"),
        ("/", "get"),
    ] {
        assert!(o["paths"][path][method].is_object(), "{path} {method}");
    }
    server.shutdown().unwrap();
}
