//! Reading a scene: JSON text → order-preserving tree → [`Scene`].
//!
//! This stage checks the *shape* of the document: JSON syntax (with line and
//! column from serde_json), object/array/number/string types, required
//! fields, unknown or duplicated keys (a typo must not be silently ignored;
//! `"comment"` is allowed in every object and `"description"` at the top),
//! and the spellings of enumerations. Every shape problem in the document is
//! reported, each with its JSON path. Meaning (lengths for the dimension,
//! signs, names that refer to other things) is checked afterwards by
//! [`super::validate`].

use super::error::{field, index, Problems};
use super::fields::{number, string, vector, Fields};
use super::model::*;
use super::tree::Json;
use crate::settings::FormulationKind;

fn pair<T>(
    p: &mut Problems,
    path: &str,
    j: &Json,
    f: impl Fn(&mut Problems, &str, &Json) -> Option<T>,
) -> Option<[T; 2]> {
    match j {
        Json::Array(items) if items.len() == 2 => {
            let a = f(p, &index(path, 0), &items[0]);
            let b = f(p, &index(path, 1), &items[1]);
            Some([a?, b?])
        }
        Json::Array(items) => {
            p.push(path, format!("expected 2 entries, got {}", items.len()));
            None
        }
        _ => {
            p.push(
                path,
                format!("expected an array of 2 entries, got {}", j.kind()),
            );
            None
        }
    }
}

fn point_ref(p: &mut Problems, path: &str, j: &Json) -> Option<PointRef> {
    match j {
        Json::String(s) => Some(PointRef::Named(s.clone())),
        Json::Array(_) => vector(p, path, j).map(PointRef::Coords),
        _ => {
            p.push(
                path,
                format!("expected a point name or coordinates, got {}", j.kind()),
            );
            None
        }
    }
}

/// Parses scene text into a [`Scene`], collecting every shape problem.
/// `default_name` is used when the scene has no `"name"`.
pub(crate) fn parse_scene(
    text: &str,
    default_name: &str,
) -> Result<Scene, Vec<super::error::Problem>> {
    let tree = parse_tree(text)?;
    scene_from_tree(&tree, default_name)
}

/// Reads scene text into the order-preserving tree (JSON syntax problems only). A UTF-8
/// byte-order mark in front (as some editors write) is skipped, as RFC 8259 §8.1 allows: it
/// was refused as "expected value at line 1 column 1", which named nothing one could see.
pub(crate) fn parse_tree(text: &str) -> Result<Json, Vec<super::error::Problem>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if let Err(e) = super::validate::check_text_length(text.len()) {
        return Err(vec![super::error::Problem::new(e.path(), e.to_string())]);
    }
    serde_json::from_str(text).map_err(|e| vec![syntax_problem(&e)])
}

/// Reads an already parsed tree into a [`Scene`], collecting every shape problem.
pub(crate) fn scene_from_tree(
    tree: &Json,
    default_name: &str,
) -> Result<Scene, Vec<super::error::Problem>> {
    let mut p = Problems::default();
    let scene = scene(&mut p, tree, default_name);
    match scene {
        Some(s) if p.list.is_empty() && p.deferred.is_empty() => Ok(s),
        Some(s) if p.list.is_empty() => {
            // subnormal numbers: refused, unless the field's own check already refuses them
            let meaning = super::validate::validate(&s);
            let mut all: Vec<super::error::Problem> = p
                .deferred
                .into_iter()
                .filter(|d| !meaning.iter().any(|m| m.path == d.path))
                .collect();
            all.extend(meaning);
            Err(all)
        }
        _ => Err(p.list),
    }
}

fn syntax_problem(e: &serde_json::Error) -> super::error::Problem {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let msg = full.strip_suffix(&suffix).unwrap_or(&full);
    super::error::Problem::new(
        "",
        format!(
            "malformed JSON at line {}, column {}: {}",
            e.line(),
            e.column(),
            msg
        ),
    )
}

pub(crate) const SCENE_KEYS: &[&str] = &[
    "name",
    "description",
    "dimension",
    "gravity",
    "bodies",
    "joints",
    "springs",
    "loads",
    "solve",
    "outputs",
    "events",
    "inputs",
    "drivers",
    "bond_graph",
];

fn scene(p: &mut Problems, j: &Json, default_name: &str) -> Option<Scene> {
    if !matches!(j, Json::Object(_)) {
        p.push(
            "",
            format!(
                "the top level of a scene must be a JSON object ({{\"bodies\": […], \"solve\": {{…}}, …}}: docs/scene-format.md §3), got {}",
                j.kind()
            ),
        );
        return None;
    }
    let f = Fields::new(p, "", j, SCENE_KEYS)?;
    // the size limits, before anything is read from a list (a scene of 200 000 bodies is
    // refused at once, not after minutes of parsing)
    let mut too_large = false;
    for list in [
        "bodies", "joints", "springs", "loads", "outputs", "events", "drivers",
    ] {
        if let Some(Json::Array(items)) = f.get(list) {
            if let Err(e) = super::validate::check_entries(list, items.len()) {
                p.push(list, e.to_string());
                too_large = true;
            }
        }
    }
    if let Some(Json::Array(bodies)) = f.get("bodies") {
        let points: usize = bodies
            .iter()
            .map(|b| match b {
                Json::Object(e) => e
                    .iter()
                    .filter(|(k, _)| k == "points")
                    .map(|(_, v)| match v {
                        Json::Object(pts) => pts.len(),
                        _ => 0,
                    })
                    .sum(),
                _ => 0,
            })
            .sum();
        if let Err(e) = super::validate::check_points(points) {
            p.push(e.path(), e.to_string());
            too_large = true;
        }
    }
    if let Some(Json::Object(g)) = f.get("bond_graph") {
        for (key, list) in [
            ("elements", "bond_graph.elements"),
            ("bonds", "bond_graph.bonds"),
        ] {
            if let Some((_, Json::Array(items))) = g.iter().find(|(k, _)| k == key) {
                if let Err(e) = super::validate::check_entries(list, items.len()) {
                    p.push(list, e.to_string());
                    too_large = true;
                }
            }
        }
    }
    if too_large {
        return None;
    }
    let name = f
        .string(p, "name")
        .unwrap_or_else(|| default_name.to_string());
    let description = f.string(p, "description");
    let dimension = match f.get("dimension") {
        None => Dimension::Planar,
        Some(Json::Number(x)) if *x == 2.0 => Dimension::Planar,
        Some(Json::Number(x)) if *x == 3.0 => Dimension::Spatial,
        Some(Json::Number(x)) => {
            p.push("dimension", format!("must be 2 or 3 (got {x})"));
            Dimension::Planar
        }
        Some(other) => {
            p.push(
                "dimension",
                format!("must be 2 or 3 (got {})", other.kind()),
            );
            Dimension::Planar
        }
    };
    let gravity = f
        .vector(p, "gravity")
        .unwrap_or_else(|| vec![0.0; dimension.coords()]);
    let bodies = f
        .array(p, "bodies")
        .iter()
        .enumerate()
        .filter_map(|(i, b)| body(p, &index("bodies", i), b, dimension))
        .collect();
    let joints = f
        .array(p, "joints")
        .iter()
        .enumerate()
        .filter_map(|(i, b)| joint(p, i, b, dimension))
        .collect();
    let springs = f
        .array(p, "springs")
        .iter()
        .enumerate()
        .filter_map(|(i, b)| spring(p, i, b))
        .collect();
    let loads = f
        .array(p, "loads")
        .iter()
        .enumerate()
        .filter_map(|(i, b)| load(p, i, b))
        .collect();
    let solve = match f.required(p, "solve") {
        Some(s) => solve(p, s)?,
        None => return None,
    };
    let outputs = f
        .array(p, "outputs")
        .iter()
        .enumerate()
        .filter_map(|(i, o)| string(p, &index("outputs", i), o))
        .collect();
    let events = f
        .array(p, "events")
        .iter()
        .enumerate()
        .filter_map(|(i, e)| event(p, i, e))
        .collect();
    // the raw bond graph is kept as a serde_json::Value, which keeps only the last of
    // duplicated keys: refuse them here, where the document order is still known
    if let Some(g) = f.get("bond_graph") {
        duplicate_keys(p, "bond_graph", g);
    }
    let inputs = f
        .array(p, "inputs")
        .iter()
        .enumerate()
        .filter_map(|(i, e)| input(p, i, e))
        .collect();
    let drivers = f
        .array(p, "drivers")
        .iter()
        .enumerate()
        .filter_map(|(i, d)| super::drivers::driver(p, i, d))
        .collect();
    let bond_graph = f.get("bond_graph").map(Json::to_value);
    Some(Scene {
        drivers,
        name,
        dimension,
        gravity,
        bodies,
        joints,
        springs,
        loads,
        solve,
        outputs,
        events,
        inputs,
        bond_graph,
        description,
    })
}

/// Reports every duplicated key inside `j` (at any depth) with its JSON path.
fn duplicate_keys(p: &mut Problems, path: &str, j: &Json) {
    match j {
        Json::Object(entries) => {
            let mut seen = std::collections::HashSet::with_capacity(entries.len());
            for (k, v) in entries {
                let kp = field(path, k);
                if !seen.insert(k.as_str()) {
                    p.push(&kp, "duplicate key");
                }
                duplicate_keys(p, &kp, v);
            }
        }
        Json::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                duplicate_keys(p, &index(path, i), v);
            }
        }
        _ => {}
    }
}

pub(crate) const INPUT_KEYS: &[&str] = &["name", "start", "unit"];

fn input(p: &mut Problems, i: usize, j: &Json) -> Option<Input> {
    let path = index("inputs", i);
    let f = Fields::new(p, &path, j, INPUT_KEYS)?;
    let name = f
        .required(p, "name")
        .and_then(|j| string(p, &f.path("name"), j));
    let start = f.number(p, "start").unwrap_or(0.0);
    let unit = f.string(p, "unit");
    Some(Input {
        name: name?,
        start,
        unit,
    })
}

pub(crate) const EVENT_KEYS: &[&str] = &["name", "when", "direction", "action"];

fn event(p: &mut Problems, i: usize, j: &Json) -> Option<Event> {
    let path = index("events", i);
    let f = Fields::new(p, &path, j, EVENT_KEYS)?;
    let name = f.string(p, "name").unwrap_or_else(|| format!("event{i}"));
    let when = f
        .required(p, "when")
        .and_then(|j| string(p, &f.path("when"), j));
    let direction = match f.string(p, "direction").as_deref() {
        None => Some(EventDirection::Both),
        Some("rising") => Some(EventDirection::Rising),
        Some("falling") => Some(EventDirection::Falling),
        Some("both") => Some(EventDirection::Both),
        Some(other) => {
            p.push(
                f.path("direction"),
                format!("must be \"rising\", \"falling\" or \"both\" (got \"{other}\")"),
            );
            None
        }
    };
    let action = match f.string(p, "action").as_deref() {
        None => Some(EventAction::Record),
        Some("stop") => Some(EventAction::Stop),
        Some("record") => Some(EventAction::Record),
        Some(other) => {
            p.push(
                f.path("action"),
                format!("must be \"stop\" or \"record\" (got \"{other}\")"),
            );
            None
        }
    };
    Some(Event {
        name,
        when: when?,
        direction: direction?,
        action: action?,
    })
}

pub(crate) const BODY_KEYS: &[&str] = &[
    "name",
    "mass",
    "inertia",
    "frame",
    "points",
    "position",
    "angle",
    "cardan",
    "velocity",
    "angular_velocity",
];

fn body(p: &mut Problems, path: &str, j: &Json, dim: Dimension) -> Option<Body> {
    let f = Fields::new(p, path, j, BODY_KEYS)?;
    let name = f
        .required(p, "name")
        .and_then(|j| string(p, &f.path("name"), j));
    let mass = f.required_number(p, "mass");
    let inertia = match f.required(p, "inertia") {
        None => None,
        Some(j @ Json::Number(_)) => number(p, &f.path("inertia"), j).map(Inertia::Planar),
        Some(j @ Json::Array(items)) if items.len() == 3 => {
            vector(p, &f.path("inertia"), j).map(|v| Inertia::Principal([v[0], v[1], v[2]]))
        }
        Some(j) => {
            p.push(
                f.path("inertia"),
                format!(
                    "expected a number (planar) or principal moments [Jx, Jy, Jz], got {}",
                    describe(j)
                ),
            );
            None
        }
    };
    let frame = match f.string(p, "frame").as_deref() {
        None | Some("inertial") => BodyFrame::Inertial,
        Some("body") => {
            // the frame's gyrator m·ω carries ω as J⁻¹ p_J: a body with no rotational inertia
            // has no angular momentum to read it from
            if matches!(inertia, Some(Inertia::Planar(j)) if j <= 0.0) {
                p.push(
                    f.path("frame"),
                    "a body-fixed frame needs a rotational inertia above 0 (this body's is 0, a point mass); use the default \"inertial\" frame".to_string(),
                );
            }
            BodyFrame::BodyFixed
        }
        Some(other) => {
            p.push(
                f.path("frame"),
                format!("must be \"inertial\" or \"body\" (got \"{other}\")"),
            );
            BodyFrame::Inertial
        }
    };
    let points = match f.get("points") {
        None => Some(Vec::new()),
        Some(Json::Object(entries)) => {
            let pp = f.path("points");
            let mut out = Vec::with_capacity(entries.len());
            let mut ok = true;
            let mut seen = std::collections::HashSet::with_capacity(entries.len());
            for (k, v) in entries.iter() {
                if !seen.insert(k.as_str()) {
                    p.push(field(&pp, k), "duplicate point name");
                    ok = false;
                } else if let Some(c) = vector(p, &field(&pp, k), v) {
                    out.push((k.clone(), c));
                } else {
                    ok = false;
                }
            }
            ok.then_some(out)
        }
        Some(other) => {
            p.push(
                f.path("points"),
                format!(
                    "expected an object {{\"name\": [x, y], ...}}, got {}",
                    other.kind()
                ),
            );
            None
        }
    };
    let position = f
        .vector(p, "position")
        .unwrap_or_else(|| vec![0.0; dim.coords()]);
    let angle = f.number(p, "angle");
    if angle.is_some() && dim == Dimension::Spatial {
        p.push(
            f.path("angle"),
            "only planar bodies have an angle; use \"cardan\": [psi, theta, phi]",
        );
    }
    let cardan = match f.get("cardan") {
        None => Some([0.0; 3]),
        Some(_) if dim == Dimension::Planar => {
            p.push(
                f.path("cardan"),
                "only spatial bodies have Cardan angles; use \"angle\"",
            );
            None
        }
        Some(j) => match vector(p, &f.path("cardan"), j) {
            Some(v) if v.len() == 3 => Some([v[0], v[1], v[2]]),
            Some(v) => {
                p.push(
                    f.path("cardan"),
                    format!("expected [psi, theta, phi], got {} numbers", v.len()),
                );
                None
            }
            None => None,
        },
    };
    let velocity_given = f.get("velocity").is_some();
    let angular_velocity_given = f.get("angular_velocity").is_some();
    let velocity = f
        .vector(p, "velocity")
        .unwrap_or_else(|| vec![0.0; dim.coords()]);
    let angular_velocity = match f.get("angular_velocity") {
        None => vec![0.0; dim.rotations()],
        Some(j @ Json::Number(_)) => number(p, &f.path("angular_velocity"), j)
            .map(|x| vec![x])
            .unwrap_or_default(),
        Some(j) => vector(p, &f.path("angular_velocity"), j).unwrap_or_default(),
    };
    Some(Body {
        name: name?,
        mass: mass?,
        inertia: inertia?,
        frame,
        points: points?,
        position,
        angle: angle.unwrap_or(0.0),
        cardan: cardan?,
        velocity,
        angular_velocity,
        velocity_given,
        angular_velocity_given,
    })
}

fn describe(j: &Json) -> String {
    match j {
        Json::Array(a) => format!("an array of {}", a.len()),
        other => other.kind().to_string(),
    }
}

pub(crate) use super::joint_kind::JOINT_KEYS;

fn joint(p: &mut Problems, i: usize, j: &Json, dim: Dimension) -> Option<Joint> {
    let path = index("joints", i);
    let f = Fields::new(p, &path, j, &JOINT_KEYS)?;
    let name = f.string(p, "name").unwrap_or_else(|| format!("joint{i}"));
    let kind_name = f
        .required(p, "type")
        .and_then(|j| string(p, &f.path("type"), j));
    let kind = kind_name
        .as_deref()
        .and_then(|k| super::joint_kind::parse(p, &f, k));
    let bodies = f
        .required(p, "bodies")
        .and_then(|j| pair(p, &f.path("bodies"), j, string));
    let points = match kind_name.as_deref() {
        Some(k) if !super::joint_kind::has_points(k) => {
            if f.get("points").is_some() {
                p.push(
                    f.path("points"),
                    format!("a {k} joint has no points (it acts at the bodies' centres)"),
                );
            }
            Some([0, 1].map(|_| PointRef::Coords(vec![0.0; dim.coords()])))
        }
        _ => f
            .required(p, "points")
            .and_then(|j| pair(p, &f.path("points"), j, point_ref)),
    };
    Some(Joint {
        name,
        kind: kind?,
        bodies: bodies?,
        points: points?,
    })
}

pub(crate) const SPRING_KEYS: &[&str] = &[
    "name",
    "bodies",
    "points",
    "stiffness",
    "rest_length",
    "damping",
];

fn spring(p: &mut Problems, i: usize, j: &Json) -> Option<Spring> {
    let path = index("springs", i);
    let f = Fields::new(p, &path, j, SPRING_KEYS)?;
    let name = f.string(p, "name").unwrap_or_else(|| format!("spring{i}"));
    let bodies = f
        .required(p, "bodies")
        .and_then(|j| pair(p, &f.path("bodies"), j, string));
    let points = f
        .required(p, "points")
        .and_then(|j| pair(p, &f.path("points"), j, point_ref));
    let stiffness = f.required_number(p, "stiffness");
    let rest_length = match f.get("rest_length") {
        None | Some(Json::Null) => Some(None),
        Some(j) => number(p, &f.path("rest_length"), j).map(Some),
    };
    let damping = f.number(p, "damping").unwrap_or(0.0);
    Some(Spring {
        name,
        bodies: bodies?,
        points: points?,
        stiffness: stiffness?,
        rest_length: rest_length?,
        damping,
    })
}

pub(crate) const LOAD_KEYS: &[&str] = &["name", "type", "body", "point", "value"];

fn load(p: &mut Problems, i: usize, j: &Json) -> Option<Load> {
    let path = index("loads", i);
    let f = Fields::new(p, &path, j, LOAD_KEYS)?;
    let name = f.string(p, "name").unwrap_or_else(|| format!("load{i}"));
    let kind = match f
        .required(p, "type")
        .and_then(|j| string(p, &f.path("type"), j))
        .as_deref()
    {
        None => None,
        Some("force") => Some(LoadKind::Force),
        Some("torque") => Some(LoadKind::Torque),
        Some(other) => {
            p.push(
                f.path("type"),
                format!("must be \"force\" or \"torque\" (got \"{other}\")"),
            );
            None
        }
    };
    let body = f
        .required(p, "body")
        .and_then(|j| string(p, &f.path("body"), j));
    let point = match f.get("point") {
        None => Some(None),
        Some(j) => point_ref(p, &f.path("point"), j).map(Some),
    };
    let value = f
        .required(p, "value")
        .and_then(|j| load_value(p, &f.path("value"), j));
    Some(Load {
        name,
        kind: kind?,
        body: body?,
        point: point?,
        value: value?,
    })
}

/// A scalar (one component) or an array of numbers.
fn components(p: &mut Problems, path: &str, j: &Json) -> Option<Vec<f64>> {
    match j {
        Json::Number(_) => number(p, path, j).map(|x| vec![x]),
        _ => vector(p, path, j),
    }
}

fn load_value(p: &mut Problems, path: &str, j: &Json) -> Option<LoadValue> {
    match j {
        Json::Number(_) => number(p, path, j).map(|x| LoadValue::Const(vec![x])),
        Json::String(s) => Some(LoadValue::Expr(vec![s.clone()])),
        Json::Array(items) if items.iter().any(|x| matches!(x, Json::String(_))) => {
            let mut out = Vec::new();
            let mut ok = true;
            for (k, item) in items.iter().enumerate() {
                match item {
                    Json::String(s) => out.push(s.clone()),
                    Json::Number(x) => out.push(format!("{x}")),
                    other => {
                        p.push(
                            index(path, k),
                            format!(
                                "expected an expression string or a number, got {}",
                                other.kind()
                            ),
                        );
                        ok = false;
                    }
                }
            }
            ok.then_some(LoadValue::Expr(out))
        }
        Json::Array(_) => vector(p, path, j).map(LoadValue::Const),
        Json::Object(_) => {
            let f = Fields::new(p, path, j, &["table"])?;
            let tj = f.required(p, "table")?;
            let tp = f.path("table");
            let tf = Fields::new(p, &tp, tj, &["t", "v"])?;
            let t = tf
                .required(p, "t")
                .and_then(|j| vector(p, &tf.path("t"), j));
            let vp = tf.path("v");
            let v = match tf.required(p, "v") {
                None => None,
                Some(Json::Array(items)) => {
                    let rows: Vec<Option<Vec<f64>>> = items
                        .iter()
                        .enumerate()
                        .map(|(k, item)| components(p, &index(&vp, k), item))
                        .collect();
                    rows.into_iter().collect::<Option<Vec<_>>>()
                }
                Some(other) => {
                    p.push(
                        vp,
                        format!("expected an array of values, got {}", other.kind()),
                    );
                    None
                }
            };
            Some(LoadValue::Table { t: t?, v: v? })
        }
        other => {
            p.push(
                path,
                format!(
                    "expected a constant, an expression string or {{\"table\": ...}}, got {}",
                    other.kind()
                ),
            );
            None
        }
    }
}

pub(crate) const SOLVE_KEYS: &[&str] = &[
    "formulation",
    "t_start",
    "t_end",
    "output_step",
    "output_times",
    "rtol",
    "atol",
    "joint_stiffness",
    "joint_damping",
    "max_steps",
    "max_wall_seconds",
    "linear_solver",
    "integrator",
    "switching_functions",
    "energy_invariant",
    "start",
];

fn solve(p: &mut Problems, j: &Json) -> Option<SolveSettings> {
    let f = Fields::new(p, "solve", j, SOLVE_KEYS)?;
    let formulation = match f.string(p, "formulation") {
        None => FormulationKind::Dae,
        Some(s) => FormulationKind::from_name(&s).unwrap_or_else(|| {
            p.push(
                f.path("formulation"),
                format!("unknown formulation \"{s}\" (expected dae, ggl, index1, decoupled, compliant_ggl or partitioned)"),
            );
            FormulationKind::Dae
        }),
    };
    let t_start = f.number(p, "t_start").unwrap_or(0.0);
    let t_end = f.required_number(p, "t_end");
    let output_step = f.number(p, "output_step");
    let output_times = f.vector(p, "output_times");
    let rtol = f.number(p, "rtol").unwrap_or(SolveSettings::DEFAULT_RTOL);
    let atol = f.number(p, "atol").unwrap_or(SolveSettings::DEFAULT_ATOL);
    let joint_stiffness = f
        .number(p, "joint_stiffness")
        .unwrap_or(SolveSettings::DEFAULT_JOINT_STIFFNESS);
    let joint_damping = f.number(p, "joint_damping").unwrap_or(0.0);
    let max_steps = match f.number(p, "max_steps") {
        None => None,
        Some(x) if x >= 1.0 && x.fract() == 0.0 && x <= u64::MAX as f64 => Some(x as u64),
        Some(x) => {
            p.push(
                f.path("max_steps"),
                format!("must be a positive integer (got {x})"),
            );
            None
        }
    };
    let max_wall_seconds = f.number(p, "max_wall_seconds");
    let linear_solver = match f.string(p, "linear_solver") {
        None => crate::settings::LinearSolverKind::Auto,
        Some(s) => crate::settings::LinearSolverKind::parse(&s).unwrap_or_else(|| {
            p.push(
                f.path("linear_solver"),
                format!("unknown linear solver \"{s}\" (expected auto, dense, sparse or klu)"),
            );
            crate::settings::LinearSolverKind::Auto
        }),
    };
    let integrator = match f.string(p, "integrator") {
        None => crate::settings::Integrator::Auto,
        Some(s) => crate::settings::Integrator::parse(&s).unwrap_or_else(|| {
            p.push(
                f.path("integrator"),
                format!("unknown integrator \"{s}\" (expected auto, adams, bdf or erk)"),
            );
            crate::settings::Integrator::Auto
        }),
    };
    let switching_functions = f.boolean(p, "switching_functions").unwrap_or(true);
    let energy_invariant = match f.string(p, "energy_invariant").as_deref() {
        None | Some("auto") => None,
        Some("always") => Some(true),
        Some("never") => Some(false),
        Some(s) => {
            p.push(
                f.path("energy_invariant"),
                format!("unknown energy invariant policy \"{s}\" (expected auto, always or never)"),
            );
            None
        }
    };
    let start_at_equilibrium = match f.string(p, "start").as_deref() {
        None | Some("given") => false,
        Some("equilibrium") => true,
        Some(s) => {
            p.push(
                f.path("start"),
                format!("unknown start \"{s}\" (expected \"given\" or \"equilibrium\")"),
            );
            false
        }
    };
    Some(SolveSettings {
        start_at_equilibrium,
        formulation,
        t_start,
        t_end: t_end?,
        output_step,
        output_times,
        rtol,
        atol,
        joint_stiffness,
        joint_damping,
        max_steps,
        max_wall_seconds,
        linear_solver,
        integrator,
        switching_functions,
        energy_invariant,
    })
}
