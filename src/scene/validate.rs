//! Checking what a scene means: every problem, each with its JSON path.
//!
//! Works on a [`Scene`] (so scenes built in code are checked too). Checks:
//! vector lengths for the dimension (2 or 3 coordinates; angular velocity 1 or
//! 3), finite numbers everywhere, mass > 0, inertia >= 0 (0 is a point mass),
//! unique non-empty body and joint names without `.`, no body called
//! `ground`, joints/springs/loads naming known bodies and points, no joint
//! between a body and itself, prismatic and hinge axes non-zero, no spherical joint in a
//! plane, a spatial revolute (hinge) with an axis and a planar one without, t_end > 0, output_step in (0, t_end],
//! output_times strictly increasing in [0, t_end], positive rtol, atol and
//! joint_stiffness, non-empty expressions, tables with strictly increasing times, outputs
//! naming known bodies/points, events with unique names and non-empty `when` (their
//! expressions are parsed when the model is built), and bodies or a bond graph present.
//!
//! Warnings (not refusals): bodies that no joint, spring or load touches.

use super::error::{field, index, Problem, Problems};
use super::model::*;

/// Largest number of output times a scene may ask for.
pub const MAX_OUTPUT_TIMES: f64 = 1e7;

/// All problems of `scene`; empty when it is valid.
pub fn validate(scene: &Scene) -> Vec<Problem> {
    let mut p = Problems::default();
    let dim = scene.dimension;
    if scene.bodies.is_empty() && scene.bond_graph.is_none() {
        p.push(
            "bodies",
            "a scene needs bodies or a bond_graph (neither is given)",
        );
    }
    if scene.bond_graph.is_some() && !(scene.bodies.is_empty() && scene.joints.is_empty()) {
        p.push(
            "bond_graph",
            "give either bodies/joints or a bond_graph, not both",
        );
    }
    vec_len(&mut p, "gravity", &scene.gravity, dim.coords());
    for (i, b) in scene.bodies.iter().enumerate() {
        body(&mut p, scene, i, b);
    }
    let mut joint_names: Vec<&str> = Vec::new();
    for (i, j) in scene.joints.iter().enumerate() {
        let path = index("joints", i);
        if joint_names.contains(&j.name.as_str()) {
            p.push(
                field(&path, "name"),
                format!("duplicate joint name '{}'", j.name),
            );
        }
        joint_names.push(&j.name);
        joint(&mut p, scene, &path, j);
    }
    for (i, s) in scene.springs.iter().enumerate() {
        let path = index("springs", i);
        attachment(&mut p, scene, &path, &s.bodies, &s.points);
        non_negative(&mut p, &field(&path, "stiffness"), s.stiffness);
        non_negative(&mut p, &field(&path, "damping"), s.damping);
        if let Some(l0) = s.rest_length {
            non_negative(&mut p, &field(&path, "rest_length"), l0);
        }
    }
    for (i, l) in scene.loads.iter().enumerate() {
        load(&mut p, scene, &index("loads", i), l);
    }
    solve(&mut p, &scene.solve);
    for (i, o) in scene.outputs.iter().enumerate() {
        output(&mut p, scene, &index("outputs", i), o);
    }
    let mut event_names: Vec<&str> = Vec::new();
    for (i, e) in scene.events.iter().enumerate() {
        let path = index("events", i);
        if e.name.is_empty() {
            p.push(field(&path, "name"), "must not be empty");
        } else if event_names.contains(&e.name.as_str()) {
            p.push(
                field(&path, "name"),
                format!("duplicate event name '{}'", e.name),
            );
        }
        event_names.push(&e.name);
        if e.when.trim().is_empty() {
            p.push(field(&path, "when"), "must be a non-empty expression");
        }
        if scene.bond_graph.is_some() {
            p.push(
                path,
                "events need bodies and joints (a raw bond graph has no event support)",
            );
        }
    }
    if scene.bond_graph.is_some() && scene.outputs.iter().any(|o| o == "reactions") {
        if let Some(i) = scene.outputs.iter().position(|o| o == "reactions") {
            p.push(
                index("outputs", i),
                "reactions need joints (a raw bond graph has none)",
            );
        }
    }
    p.list
}

/// Bodies that no joint, spring or load touches, when the scene has joints or
/// springs at all (a lone free body is intentional, e.g. a spinning top).
pub fn warnings(scene: &Scene) -> Vec<Problem> {
    if scene.joints.is_empty() && scene.springs.is_empty() {
        return Vec::new();
    }
    let touched = |name: &str| {
        scene
            .joints
            .iter()
            .any(|j| j.bodies.iter().any(|b| b == name))
            || scene
                .springs
                .iter()
                .any(|s| s.bodies.iter().any(|b| b == name))
            || scene.loads.iter().any(|l| l.body == name)
    };
    scene
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| !touched(&b.name))
        .map(|(i, b)| {
            Problem::new(
                index("bodies", i),
                format!("'{}' is not connected to anything", b.name),
            )
        })
        .collect()
}

fn finite(p: &mut Problems, path: &str, x: f64) -> bool {
    if !x.is_finite() {
        p.push(path, format!("must be finite (got {x})"));
    }
    x.is_finite()
}

fn positive(p: &mut Problems, path: &str, x: f64) {
    if !(x > 0.0 && x.is_finite()) {
        p.push(path, format!("must be > 0 and finite (got {x})"));
    }
}

fn non_negative(p: &mut Problems, path: &str, x: f64) {
    if !(x >= 0.0 && x.is_finite()) {
        p.push(path, format!("must be >= 0 and finite (got {x})"));
    }
}

/// Checks length and finiteness of a vector.
fn vec_len(p: &mut Problems, path: &str, v: &[f64], n: usize) {
    if v.len() != n {
        p.push(path, format!("expected {n} components, got {}", v.len()));
    }
    for (k, x) in v.iter().enumerate() {
        finite(p, &index(path, k), *x);
    }
}

fn body(p: &mut Problems, scene: &Scene, i: usize, b: &Body) {
    let dim = scene.dimension;
    let path = index("bodies", i);
    let np = field(&path, "name");
    if b.name.is_empty() {
        p.push(&np, "must not be empty");
    } else if b.name == GROUND {
        p.push(
            &np,
            "'ground' is reserved for the fixed body; do not list it",
        );
    } else if b.name.contains('.') {
        p.push(
            &np,
            format!("'{}' must not contain '.' (outputs use body.point)", b.name),
        );
    } else if scene.bodies[..i].iter().any(|o| o.name == b.name) {
        p.push(&np, format!("duplicate body name '{}'", b.name));
    }
    positive(p, &field(&path, "mass"), b.mass);
    let ip = field(&path, "inertia");
    match (b.inertia, dim) {
        (Inertia::Planar(j), Dimension::Planar) => non_negative(p, &ip, j),
        (Inertia::Principal(js), Dimension::Spatial) => {
            for (k, j) in js.iter().enumerate() {
                non_negative(p, &index(&ip, k), *j);
            }
            let [a, b2, c] = js;
            if js.iter().all(|x| x.is_finite() && *x > 0.0)
                && (a > b2 + c || b2 > a + c || c > a + b2)
            {
                p.push(&ip, format!("principal moments {js:?} violate the triangle inequality (no rigid body has them)"));
            }
        }
        (Inertia::Planar(_), Dimension::Spatial) => {
            p.push(&ip, "a spatial body needs principal moments [Jx, Jy, Jz]")
        }
        (Inertia::Principal(_), Dimension::Planar) => {
            p.push(&ip, "a planar body needs a scalar inertia")
        }
    }
    let pp = field(&path, "points");
    for (name, c) in &b.points {
        let path_k = field(&pp, name);
        if name.is_empty() || name.contains('.') {
            p.push(&path_k, "a point name must be non-empty and contain no '.'");
        }
        vec_len(p, &path_k, c, dim.coords());
    }
    vec_len(p, &field(&path, "position"), &b.position, dim.coords());
    vec_len(p, &field(&path, "velocity"), &b.velocity, dim.coords());
    let wp = field(&path, "angular_velocity");
    if dim == Dimension::Planar && b.angular_velocity.len() != 1 {
        p.push(
            &wp,
            format!(
                "a planar body has one angular velocity, got {}",
                b.angular_velocity.len()
            ),
        );
    } else {
        vec_len(p, &wp, &b.angular_velocity, dim.rotations());
    }
    finite(p, &field(&path, "angle"), b.angle);
    for (k, x) in b.cardan.iter().enumerate() {
        finite(p, &index(&field(&path, "cardan"), k), *x);
    }
}

/// Checks that `name` is ground or a known body and that `point` exists on it.
fn point_on(
    p: &mut Problems,
    scene: &Scene,
    body_path: &str,
    name: &str,
    point_path: &str,
    point: &PointRef,
) {
    let dim = scene.dimension;
    if name == GROUND {
        match point {
            PointRef::Coords(c) => vec_len(p, point_path, c, dim.coords()),
            PointRef::Named(n) => p.push(
                point_path,
                format!("ground has no named points; give global coordinates instead of '{n}'"),
            ),
        }
        return;
    }
    let Some(bi) = scene.body_index(name) else {
        p.push(body_path, format!("unknown body '{name}'"));
        return;
    };
    let b = &scene.bodies[bi];
    match point {
        PointRef::Coords(c) => vec_len(p, point_path, c, dim.coords()),
        PointRef::Named(n) => {
            if b.point(n).is_none() {
                let names: Vec<&str> = b.point_names().collect();
                let has = if names.is_empty() {
                    "it has no named points".to_string()
                } else {
                    format!("it has: {}", names.join(", "))
                };
                p.push(
                    point_path,
                    format!("body '{name}' has no point '{n}' ({has})"),
                );
            }
        }
    }
}

fn attachment(
    p: &mut Problems,
    scene: &Scene,
    path: &str,
    bodies: &[String; 2],
    points: &[PointRef; 2],
) {
    let bp = field(path, "bodies");
    let pp = field(path, "points");
    for k in 0..2 {
        point_on(
            p,
            scene,
            &index(&bp, k),
            &bodies[k],
            &index(&pp, k),
            &points[k],
        );
    }
    if bodies[0] == bodies[1] {
        p.push(
            bp,
            format!("both ends are on the same body '{}'", bodies[0]),
        );
    }
}

fn joint(p: &mut Problems, scene: &Scene, path: &str, j: &Joint) {
    if j.name.is_empty() {
        p.push(field(path, "name"), "must not be empty");
    }
    attachment(p, scene, path, &j.bodies, &j.points);
    let tp = field(path, "type");
    match (&j.kind, scene.dimension) {
        (JointKind::Spherical, Dimension::Planar) => p.push(
            tp,
            "a spherical joint needs a spatial scene (dimension 3); use revolute in the plane",
        ),
        (JointKind::Revolute, Dimension::Spatial) => p.push(
            field(path, "axis"),
            "a revolute joint in a spatial scene is a hinge and needs an axis (the hinge axis in the frame of the first body, global for ground; body 2 keeps the relative orientation of the initial configuration about it); use spherical for a ball joint",
        ),
        (JointKind::Hinge { .. }, Dimension::Planar) => p.push(
            field(path, "axis"),
            "only a prismatic joint has an axis in a planar scene (a planar revolute pins about z)",
        ),
        (JointKind::Prismatic { axis } | JointKind::Hinge { axis }, dim) => {
            let ap = field(path, "axis");
            vec_len(p, &ap, axis, dim.coords());
            let norm2: f64 = axis.iter().map(|x| x * x).sum();
            if norm2.is_finite() && norm2 == 0.0 {
                p.push(ap, "must be a non-zero direction");
            }
        }
        _ => {}
    }
}

fn load(p: &mut Problems, scene: &Scene, path: &str, l: &Load) {
    let bp = field(path, "body");
    if l.body == GROUND {
        p.push(&bp, "a load on ground does nothing; load a moving body");
    } else if scene.body_index(&l.body).is_none() {
        p.push(&bp, format!("unknown body '{}'", l.body));
    } else if let Some(pt) = &l.point {
        point_on(p, scene, &bp, &l.body, &field(path, "point"), pt);
    }
    if l.kind == LoadKind::Torque && l.point.is_some() {
        p.push(field(path, "point"), "a torque has no point of application");
    }
    let n = l.components(scene.dimension);
    let vp = field(path, "value");
    match &l.value {
        LoadValue::Const(v) => vec_len(p, &vp, v, n),
        LoadValue::Expr(e) => {
            if e.len() != n {
                p.push(&vp, format!("expected {n} expressions, got {}", e.len()));
            }
            for (k, s) in e.iter().enumerate() {
                let ep = if e.len() == 1 {
                    vp.clone()
                } else {
                    index(&vp, k)
                };
                expression(p, &ep, s);
            }
        }
        LoadValue::Table { t, v } => {
            let tp = field(&vp, "table");
            let t_path = field(&tp, "t");
            if t.is_empty() {
                p.push(&t_path, "needs at least one sample");
            }
            for (k, x) in t.iter().enumerate() {
                finite(p, &index(&t_path, k), *x);
            }
            if !t.windows(2).all(|w| w[1] > w[0]) {
                p.push(&t_path, "must be strictly increasing");
            }
            let v_path = field(&tp, "v");
            if v.len() != t.len() {
                p.push(
                    &v_path,
                    format!(
                        "expected {} values (one per time in t), got {}",
                        t.len(),
                        v.len()
                    ),
                );
            }
            for (k, row) in v.iter().enumerate() {
                vec_len(p, &index(&v_path, k), row, n);
            }
        }
    }
}

/// Light checks of an expression string; the expression parser does the rest.
fn expression(p: &mut Problems, path: &str, s: &str) {
    if s.trim().is_empty() {
        p.push(path, "expression must not be empty");
        return;
    }
    let mut depth = 0i64;
    for c in s.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ => {}
        }
        if depth < 0 {
            break;
        }
    }
    if depth != 0 {
        p.push(path, format!("unbalanced parentheses in \"{s}\""));
    }
}

fn solve(p: &mut Problems, s: &SolveSettings) {
    positive(p, "solve.t_end", s.t_end);
    let t0 = s.t_start;
    if !t0.is_finite() {
        p.push("solve.t_start", format!("must be finite (got {t0})"));
    } else if s.t_end.is_finite() && s.t_end <= t0 {
        p.push(
            "solve.t_end",
            format!("must be > t_start = {t0} (got {})", s.t_end),
        );
    }
    let span = s.t_end - if t0.is_finite() { t0 } else { 0.0 };
    if let Some(h) = s.output_step {
        if !(h > 0.0 && h.is_finite()) {
            p.push(
                "solve.output_step",
                format!("must be > 0 and finite (got {h})"),
            );
        } else if span.is_finite() && span > 0.0 && h > span {
            p.push(
                "solve.output_step",
                format!("must be <= t_end - t_start = {span} (got {h})"),
            );
        } else if span / h > MAX_OUTPUT_TIMES {
            p.push(
                "solve.output_step",
                format!("gives more than {MAX_OUTPUT_TIMES:e} output times"),
            );
        }
    }
    if let Some(times) = &s.output_times {
        if s.output_step.is_some() {
            p.push(
                "solve.output_times",
                "give output_step or output_times, not both",
            );
        }
        if times.is_empty() {
            p.push("solve.output_times", "needs at least one time");
        }
        for (k, t) in times.iter().enumerate() {
            if !(t.is_finite() && *t >= t0 && *t <= s.t_end) {
                p.push(
                    index("solve.output_times", k),
                    format!("must lie in [{t0}, t_end = {}] (got {t})", s.t_end),
                );
            }
        }
        if !times.windows(2).all(|w| w[1] > w[0]) {
            p.push("solve.output_times", "must be strictly increasing");
        }
    }
    positive(p, "solve.rtol", s.rtol);
    positive(p, "solve.atol", s.atol);
    positive(p, "solve.joint_stiffness", s.joint_stiffness);
    non_negative(p, "solve.joint_damping", s.joint_damping);
    if s.max_steps == Some(0) {
        p.push("solve.max_steps", "must be a positive integer (got 0)");
    }
    if let Some(w) = s.max_wall_seconds {
        positive(p, "solve.max_wall_seconds", w);
    }
}

fn output(p: &mut Problems, scene: &Scene, path: &str, o: &str) {
    match o.split_once('.') {
        None => {
            if !SCALAR_OUTPUTS.contains(&o) {
                p.push(
                    path,
                    format!(
                        "unknown output '{o}' (expected body.point, body.column or one of: {})",
                        SCALAR_OUTPUTS.join(", ")
                    ),
                );
            }
        }
        Some((b, rest)) => {
            let Some(bi) = scene.body_index(b) else {
                p.push(path, format!("unknown body '{b}'"));
                return;
            };
            let body = &scene.bodies[bi];
            // `b.P.x`, `b.P.vx`, … : one coordinate or velocity component of a named point
            if let Some((pt, comp)) = rest.split_once('.') {
                let comps: &[&str] = match scene.dimension {
                    Dimension::Planar => &["x", "y", "vx", "vy"],
                    Dimension::Spatial => &["x", "y", "z", "vx", "vy", "vz"],
                };
                if body.point(pt).is_none() {
                    let names: Vec<&str> = body.point_names().collect();
                    p.push(
                        path,
                        format!(
                            "body '{b}' has no point '{pt}' (it has: {})",
                            names.join(", ")
                        ),
                    );
                } else if !comps.contains(&comp) {
                    p.push(
                        path,
                        format!(
                            "unknown point component '{comp}' (expected one of: {})",
                            comps.join(", ")
                        ),
                    );
                }
                return;
            }
            if body.point(rest).is_none() && !BODY_COLUMNS.contains(&rest) {
                let names: Vec<&str> = body.point_names().collect();
                p.push(
                    path,
                    format!(
                        "body '{b}' has no point '{rest}' (it has: {})",
                        names.join(", ")
                    ),
                );
            }
        }
    }
}
