//! Checking what a scene means: every problem, each with its JSON path.
//!
//! Works on a [`Scene`] (so scenes built in code are checked too). Checks:
//! vector lengths for the dimension (2 or 3 coordinates; angular velocity 1 or
//! 3), finite numbers everywhere, mass > 0, inertia >= 0 (0 is a point mass),
//! unique non-empty body and joint names without `.`, no body called
//! `ground`, joints/springs/loads naming known bodies and points, no joint
//! between a body and itself, prismatic and hinge axes non-zero, no spherical joint in a
//! plane, a spatial revolute (hinge) with an axis and a planar one without, t_end > 0, output_step in (0, t_end],
//! output_times strictly increasing in [0, t_end], non-empty expressions, tables with strictly
//! increasing times, outputs naming known bodies/points, events with unique names and non-empty
//! `when` (their expressions are parsed when the model is built), and bodies or a bond graph
//! present.
//!
//! Single quantities go through one public function each, shared with the command-line
//! flags: [`check_mass`] and [`check_inertia`] (0, or in `[1e-100, 1e100]`: no subnormal or
//! absurd masses), [`check_rtol`] (`[1e-15, 1]`), [`check_atol`] (`>= 1e-100`, at most the
//! mechanism's [`length_scale`]), [`check_joint_stiffness`] (`[1e-100, 1e16]`) and
//! [`check_t_end`] (`> 0`, at most 1e7 output rows). Each returns a typed [`BoundError`] whose
//! message states the rule.
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
    solve(&mut p, &scene.solve, length_scale(scene));
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
    super::inputs::validate(&mut p, scene);
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

/// Records the refusal of a bound check at `path`.
fn bound(p: &mut Problems, path: &str, r: Result<(), BoundError>) {
    if let Err(e) = r {
        p.push(path, e.to_string());
    }
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
    bound(p, &field(&path, "mass"), check_mass(b.mass));
    let ip = field(&path, "inertia");
    match (b.inertia, dim) {
        (Inertia::Planar(j), Dimension::Planar) => bound(p, &ip, check_inertia(j)),
        (Inertia::Principal(js), Dimension::Spatial) => {
            for (k, j) in js.iter().enumerate() {
                bound(p, &index(&ip, k), check_inertia(*j));
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
    // byte offset of the offending parenthesis: the first unmatched ')' or the last unclosed '('
    let mut open = Vec::new();
    let mut at = None;
    for (b, c) in s.char_indices() {
        match c {
            '(' => {
                depth += 1;
                open.push(b);
            }
            ')' => {
                depth -= 1;
                open.pop();
            }
            _ => {}
        }
        if depth < 0 {
            at = Some(b);
            break;
        }
    }
    if depth != 0 {
        let pos = at.or(open.last().copied()).unwrap_or(0);
        p.push(
            path,
            format!("unbalanced parentheses in {}", crate::expr::excerpt(s, pos)),
        );
    }
}

fn solve(p: &mut Problems, s: &SolveSettings, length: Option<f64>) {
    bound(p, "solve.t_end", check_t_end(s.t_end, None));
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
    bound(p, "solve.rtol", check_rtol(s.rtol));
    bound(p, "solve.atol", check_atol(s.atol, length));
    bound(
        p,
        "solve.joint_stiffness",
        check_joint_stiffness(s.joint_stiffness),
    );
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
        // a raw graph's outputs name its own columns (checked against the graph)
        Some(_) if scene.bond_graph.is_some() => {}
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

// ---------------------------------------------------------------------------------------------
// Bounds on single quantities, shared by the scene and the command-line flags
// ---------------------------------------------------------------------------------------------

/// Smallest positive mass (kg) or inertia (kg·m²) a scene may give: below it squares and
/// products with other scene quantities (`m²`, `m·g·L`, `J ω²`) drift toward the subnormal
/// range and the mass matrix loses its digits.
pub const MIN_MASS: f64 = 1e-100;
/// Largest mass (kg) or inertia (kg·m²) a scene may give: above it `m²` and the energies
/// overflow toward infinity.
pub const MAX_MASS: f64 = 1e100;
/// Smallest relative tolerance: about 4.5 × the double-precision epsilon; below it the error
/// test asks for digits a double does not hold, and SUNDIALS cannot deliver it.
pub const MIN_RTOL: f64 = 1e-15;
/// Largest relative tolerance: 1 (100 % error) already controls nothing.
pub const MAX_RTOL: f64 = 1.0;
/// Smallest absolute tolerance: a positive normal double well above the subnormal range.
pub const MIN_ATOL: f64 = 1e-100;
/// Smallest stiffness of the decoupled twin's joint springs (N/m, or N·m/rad for angle rows):
/// softer springs hold nothing (a joint force of 1 N would stretch them by 1e100 m).
pub const MIN_JOINT_STIFFNESS: f64 = 1e-100;
/// Largest stiffness of the decoupled twin's joint springs (N/m): above it the spring force
/// `k g` is dominated by the rounding error of the positions (`k · 2.2e-16 m` is 2 N at 1e16
/// on a mechanism of 1 m), and the oscillation `√(k/m)` cannot be resolved in any number of
/// steps.
pub const MAX_JOINT_STIFFNESS: f64 = 1e16;

/// Why a number given for a scene field or a command-line flag cannot be used.
///
/// The message says what the rule is; the caller adds the field's JSON path (`solve.rtol`)
/// or the flag (`--rtol`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BoundError {
    /// Zero, negative, NaN or infinite where a positive number is needed.
    #[error("must be > 0 and finite (got {value})")]
    NotPositive {
        /// The value given.
        value: f64,
    },
    /// Negative, NaN or infinite where zero or a positive number is needed.
    #[error("must be >= 0 and finite (got {value})")]
    Negative {
        /// The value given.
        value: f64,
    },
    /// Below the smallest value that makes sense.
    #[error("must be >= {min:e} (got {value:e}): {why}")]
    TooSmall {
        /// The value given.
        value: f64,
        /// The bound.
        min: f64,
        /// Why the bound is there.
        why: &'static str,
    },
    /// Above the largest value that makes sense.
    #[error("must be <= {max:e} (got {value:e}): {why}")]
    TooLarge {
        /// The value given.
        value: f64,
        /// The bound.
        max: f64,
        /// Why the bound is there.
        why: &'static str,
    },
}

fn finite_positive(value: f64) -> Result<(), BoundError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(BoundError::NotPositive { value })
    }
}

fn within(
    value: f64,
    min: f64,
    max: f64,
    why_min: &'static str,
    why_max: &'static str,
) -> Result<(), BoundError> {
    finite_positive(value)?;
    if value < min {
        Err(BoundError::TooSmall {
            value,
            min,
            why: why_min,
        })
    } else if value > max {
        Err(BoundError::TooLarge {
            value,
            max,
            why: why_max,
        })
    } else {
        Ok(())
    }
}

const MASS_SMALL: &str = "smaller masses and inertias underflow in the mass matrix and the energies (rule: 0 < m, and 1e-100 <= m <= 1e100)";
const MASS_LARGE: &str = "larger masses and inertias overflow in the mass matrix and the energies (rule: 1e-100 <= m <= 1e100)";

/// A body's mass (kg): finite, in `[MIN_MASS, MAX_MASS]` = `[1e-100, 1e100]`.
///
/// `1e-320` (a subnormal) and `1e300` are refused: their squares and products with the scene's
/// other quantities leave the normal range of doubles, and the solution would be garbage.
pub fn check_mass(value: f64) -> Result<(), BoundError> {
    within(value, MIN_MASS, MAX_MASS, MASS_SMALL, MASS_LARGE)
}

/// One (principal) moment of inertia (kg·m²): 0 (a point mass, no rotation inertia), or in
/// `[MIN_MASS, MAX_MASS]` = `[1e-100, 1e100]` as a mass.
pub fn check_inertia(value: f64) -> Result<(), BoundError> {
    if !(value.is_finite() && value >= 0.0) {
        return Err(BoundError::Negative { value });
    }
    if value == 0.0 {
        return Ok(());
    }
    within(value, MIN_MASS, MAX_MASS, MASS_SMALL, MASS_LARGE)
}

/// The relative tolerance (`solve.rtol`, `--rtol`): in `[MIN_RTOL, MAX_RTOL]` = `[1e-15, 1]`.
pub fn check_rtol(value: f64) -> Result<(), BoundError> {
    within(
        value,
        MIN_RTOL,
        MAX_RTOL,
        "a double holds about 16 digits, and SUNDIALS cannot deliver a tighter relative tolerance",
        "a relative error of 100 % or more controls nothing",
    )
}

/// The absolute tolerance (`solve.atol`, `--atol`): finite, `>= MIN_ATOL` (1e-100) and, when the
/// mechanism has a size (`length_scale`, see [`length_scale`]: the largest distance of a body
/// centre, body point or ground point from the origin, or between them), no larger than that
/// size — an absolute error as large as the mechanism controls nothing. Raw bond graphs have no
/// size (`None`): only the first two rules apply.
pub fn check_atol(value: f64, length_scale: Option<f64>) -> Result<(), BoundError> {
    finite_positive(value)?;
    if value < MIN_ATOL {
        return Err(BoundError::TooSmall {
            value,
            min: MIN_ATOL,
            why: "an absolute tolerance this close to the subnormal range is rounding noise",
        });
    }
    if let Some(l) = length_scale.filter(|l| *l > 0.0 && l.is_finite()) {
        if value > l {
            return Err(BoundError::TooLarge {
                value,
                max: l,
                why: "the mechanism's size (largest distance of a body centre or point from the origin): an absolute error as large as the mechanism controls nothing",
            });
        }
    }
    Ok(())
}

/// The decoupled twin's joint stiffness (`solve.joint_stiffness`, `--joint-stiffness`, N/m):
/// in `[MIN_JOINT_STIFFNESS, MAX_JOINT_STIFFNESS]` = `[1e-100, 1e16]`.
///
/// Inside these bounds a stiffness can still give a meaningless twin (springs that start
/// stretched by more than the bodies' size); that is a warning, given when the twin is built
/// with the joint forces known ([`crate::dae::decoupled::prestress_warning`]).
pub fn check_joint_stiffness(value: f64) -> Result<(), BoundError> {
    within(
        value,
        MIN_JOINT_STIFFNESS,
        MAX_JOINT_STIFFNESS,
        "a softer joint spring holds nothing (a joint force of 1 N would stretch it by more than 1e100 m)",
        "the spring force k·g is then dominated by the rounding error of the positions (k · 2.2e-16 m is 2 N at 1e16 on a 1 m mechanism), and √(k/m) cannot be resolved by any step",
    )
}

/// The end time (`solve.t_end`, `--t-end`, s): finite, `> 0`, and with `output_step` (the
/// scene's, when given) at most [`MAX_OUTPUT_TIMES`] output times — every row is kept in
/// memory, and `--t-end 1e12` at a step of 0.01 s would ask for 1e14 of them.
pub fn check_t_end(value: f64, output_step: Option<f64>) -> Result<(), BoundError> {
    finite_positive(value)?;
    if let Some(h) = output_step.filter(|h| *h > 0.0 && h.is_finite()) {
        let max = MAX_OUTPUT_TIMES * h;
        if value / h > MAX_OUTPUT_TIMES {
            return Err(BoundError::TooLarge {
                value,
                max,
                why: "at the scene's output_step this asks for more than 1e7 output rows; raise solve.output_step or give solve.output_times",
            });
        }
    }
    Ok(())
}

/// The size of a mechanism (m): the largest distance of a body centre, a body point (from the
/// origin, at the initial configuration, ignoring rotation: `|position| + |point|`) or a ground
/// point from the origin. `None` for a scene without bodies (a raw bond graph), or when every
/// body sits at the origin with no points.
pub fn length_scale(scene: &Scene) -> Option<f64> {
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut l: f64 = 0.0;
    for b in &scene.bodies {
        let r = norm(&b.position);
        let arm = b.points.iter().map(|(_, c)| norm(c)).fold(0.0, f64::max);
        l = l.max(r + arm);
    }
    for j in &scene.joints {
        for (name, p) in j.bodies.iter().zip(&j.points) {
            if let (true, PointRef::Coords(c)) = (name == GROUND, p) {
                l = l.max(norm(c));
            }
        }
    }
    (l > 0.0 && l.is_finite()).then_some(l)
}
