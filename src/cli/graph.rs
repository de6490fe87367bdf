//! `bondmech graph`: the scene's bond graph drawn (DOT, SVG through Graphviz), its causality
//! report, or the graph written back as a raw bond-graph scene.

use bondmech::Model;

use super::args::GraphArgs;
use super::failure::{options_error, CliError};
use super::output::{check_outputs, stdout_write, svg, write};
use super::scene_input::read_scene;

/// `bondmech graph SCENE`.
pub(crate) fn graph(args: GraphArgs) -> Result<(), CliError> {
    let GraphArgs {
        scene,
        causality,
        decoupled,
        as_scene,
        out,
        collapse,
        expand,
    } = args;
    if as_scene {
        if let Some(p) = out.as_ref() {
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            if !ext.eq_ignore_ascii_case("json") {
                return Err(options_error(format!(
                    "--out {}: --as-scene writes a JSON scene; give --out a .json file",
                    p.display()
                )));
            }
        }
        check_outputs(&[&scene], &[("--out", out.as_deref())])?;
        let scene = read_scene(&scene)?;
        // what a raw graph cannot carry is said, not dropped silently
        if !scene.events.is_empty() {
            super::output::print_warnings(&[format!(
                "events: the scene's {} events are not carried over by --as-scene (a raw bond graph scene has none; add them to the written scene by hand)",
                scene.events.len()
            )]);
        }
        let v = bondmech::graph::bond_graph_scene(&scene)?;
        let text = serde_json::to_string_pretty(&v).expect("scene serialises") + "\n";
        return match out {
            Some(p) => Ok(write(&p, &text)?),
            None => Ok(stdout_write(&text)?),
        };
    }
    // the causality report is JSON: refuse to write it into a drawing's file
    if let Some(p) = out.as_ref().filter(|_| causality) {
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("svg") || ext.eq_ignore_ascii_case("dot") {
            return Err(options_error(format!(
                "--out {}: --causality writes the causality report as JSON; give --out a .json file (or draw the graph without --causality)",
                p.display()
            )));
        }
    }
    check_outputs(&[&scene], &[("--out", out.as_deref())])?;
    let model = Model::new(&read_scene(&scene)?)?;
    if decoupled && model.is_raw_bond_graph() {
        return Err(options_error(
            "--decoupled: a raw bond graph has no joints to decouple".into(),
        ));
    }
    // the scene's own `solve.formulation: "decoupled"` draws the twin too
    let decoupled = decoupled
        || (!model.is_raw_bond_graph()
            && model.scene().solve.formulation == bondmech::FormulationKind::Decoupled);
    let variant = if decoupled {
        bondmech::mech::Variant::Decoupled
    } else {
        bondmech::mech::Variant::Pinned
    };
    let g = model.scene_graph(variant)?;
    let text = if causality {
        serde_json::to_string_pretty(&g.report()).expect("report serialises") + "\n"
    } else if collapse || expand {
        g.dot_with(collapse)
    } else {
        g.dot()
    };
    match out {
        Some(p) if p.extension().is_some_and(|e| e == "svg") => Ok(svg(&text, &p)?),
        Some(p) => Ok(write(&p, &text)?),
        None => Ok(stdout_write(&text)?),
    }
}
