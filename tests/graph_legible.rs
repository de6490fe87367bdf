//! `bondmech graph --out FILE.svg` stays legible on large mechanisms: Bricard's drawing is at
//! most 4000 pt on its longer side with no text longer than 60 characters (collapsed by
//! default, and expanded on request), and numbers carry no float noise (Andrews' squeezer).
//! Needs Graphviz `dot` (installed by scripts/install-deps.sh).

mod support;

use support::cli::{bondmech, scene, tmp};

/// (width, height) in pt and every text of a Graphviz SVG.
fn read_svg(path: &std::path::Path) -> ((f64, f64), Vec<String>) {
    let svg = std::fs::read_to_string(path).unwrap();
    let root = &svg[svg.find("<svg").unwrap()..];
    let attr = |name: &str| -> f64 {
        let key = format!("{name}=\"");
        let s = root.find(&key).unwrap() + key.len();
        let v = &root[s..s + root[s..].find('"').unwrap()];
        v.trim_end_matches("pt").parse().unwrap()
    };
    let mut texts = Vec::new();
    let mut rest = svg.as_str();
    while let Some(i) = rest.find("<text") {
        rest = &rest[i..];
        let body = rest.find('>').unwrap() + 1;
        let end = rest.find("</text>").unwrap();
        let t = rest[body..end]
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&amp;", "&")
            .replace("&#45;", "-")
            .replace("&quot;", "\"")
            .replace("&#160;", " ");
        texts.push(t);
        rest = &rest[end..];
    }
    ((attr("width"), attr("height")), texts)
}

fn graph_svg(file: &str, extra: &[&str]) -> ((f64, f64), Vec<String>) {
    let out_path = tmp(&format!("legible-{file}{}.svg", extra.join("")));
    let s = scene(file);
    let mut args = vec!["graph", s.as_str()];
    args.extend_from_slice(extra);
    args.extend(["--out", out_path.to_str().unwrap()]);
    let out = bondmech(&args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    read_svg(&out_path)
}

#[test]
fn bricard_graph_fits_4000_pt_with_labels_of_at_most_60_characters() {
    for extra in [&[][..], &["--expand"][..], &["--collapse"][..]] {
        let ((w, h), texts) = graph_svg("bricard.json", extra);
        assert!(w.max(h) <= 4000.0, "{extra:?}: the drawing is {w} × {h} pt");
        assert!(texts.len() > 5, "{extra:?}: {} texts", texts.len());
        let longest = texts.iter().max_by_key(|t| t.chars().count()).unwrap();
        assert!(
            longest.chars().count() <= 60,
            "{extra:?}: a label of {} characters: {longest}",
            longest.chars().count()
        );
    }
}

#[test]
fn andrews_graph_numbers_carry_no_float_noise() {
    let ((w, h), texts) = graph_svg("andrews_squeezer.json", &["--expand"]);
    assert!(w.max(h) <= 4000.0);
    for t in &texts {
        // a run of 12 or more digits is float noise (0.0007400000000000011)
        let mut run = 0;
        for c in t.chars() {
            run = if c.is_ascii_digit() { run + 1 } else { 0 };
            assert!(run < 12, "float noise in {t}");
        }
        assert!(t.chars().count() <= 60, "{t}");
    }
    assert!(
        texts.iter().any(|t| t.contains("0.00074")),
        "the modulus constant 0.00074 is printed short"
    );
}
