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

use super::error::{comma_in_name, field, index, Problem, Problems};
use super::model::*;

/// Largest number of output times a scene may ask for.
pub const MAX_OUTPUT_TIMES: f64 = 1e7;

/// Most entries a scene may list in each of `bodies`, `joints`, `springs`, `loads`, `events`,
/// `outputs` and a bond graph's `elements` and `bonds` (far beyond what fits in memory as a
/// model: 6000 free bodies already need ~10 GiB, see [`crate::mech::size`]).
pub const MAX_SCENE_ENTRIES: usize = 100_000;

/// Most named points a scene may give, all bodies together.
pub const MAX_SCENE_POINTS: usize = 1_000_000;

/// Longest scene text, in bytes (64 MiB), refused before it is parsed.
pub const MAX_SCENE_BYTES: usize = 64 << 20;

/// Largest wall-clock budget or grace period, in seconds (about 31.7 years): a larger number
/// does not fit a [`std::time::Duration`] on every platform and means "no limit", which is
/// said by leaving the field out.
pub const MAX_WALL_SECONDS: f64 = 1e9;

/// A scene beyond the documented size limits ([`MAX_SCENE_ENTRIES`], [`MAX_SCENE_POINTS`],
/// [`MAX_SCENE_BYTES`]): refused at once, before anything is built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneSizeError {
    /// Too many entries in one list.
    #[error("{count} entries, more than the limit of {limit} a scene may list (docs/scene-format.md, size limits)")]
    TooManyEntries {
        /// The list (`bodies`, `joints`, `bond_graph.elements`, …).
        list: &'static str,
        /// Its length.
        count: usize,
        /// [`MAX_SCENE_ENTRIES`].
        limit: usize,
    },
    /// Too many named points.
    #[error("{count} named points in all, more than the limit of {limit} (docs/scene-format.md, size limits)")]
    TooManyPoints {
        /// The number of points.
        count: usize,
        /// [`MAX_SCENE_POINTS`].
        limit: usize,
    },
    /// The scene text is too long.
    #[error("the scene is {bytes} bytes long, more than the limit of {limit} bytes (docs/scene-format.md, size limits)")]
    TooLong {
        /// Its length (at least; reading stops past the limit).
        bytes: usize,
        /// [`MAX_SCENE_BYTES`].
        limit: usize,
    },
}

impl SceneSizeError {
    /// The JSON path the refusal is reported at.
    pub fn path(&self) -> &'static str {
        match self {
            SceneSizeError::TooManyEntries { list, .. } => list,
            SceneSizeError::TooManyPoints { .. } => "bodies",
            SceneSizeError::TooLong { .. } => "",
        }
    }
}

/// Refuses a list of `count` entries at `list` beyond [`MAX_SCENE_ENTRIES`].
pub fn check_entries(list: &'static str, count: usize) -> Result<(), SceneSizeError> {
    if count > MAX_SCENE_ENTRIES {
        Err(SceneSizeError::TooManyEntries {
            list,
            count,
            limit: MAX_SCENE_ENTRIES,
        })
    } else {
        Ok(())
    }
}

/// Refuses `count` named points beyond [`MAX_SCENE_POINTS`].
pub fn check_points(count: usize) -> Result<(), SceneSizeError> {
    if count > MAX_SCENE_POINTS {
        Err(SceneSizeError::TooManyPoints {
            count,
            limit: MAX_SCENE_POINTS,
        })
    } else {
        Ok(())
    }
}

/// Refuses a scene text of `bytes` bytes beyond [`MAX_SCENE_BYTES`].
pub fn check_text_length(bytes: usize) -> Result<(), SceneSizeError> {
    if bytes > MAX_SCENE_BYTES {
        Err(SceneSizeError::TooLong {
            bytes,
            limit: MAX_SCENE_BYTES,
        })
    } else {
        Ok(())
    }
}

/// The size limits on a scene built in code (a scene read from text was checked while read).
pub fn check_scene_size(scene: &Scene) -> Result<(), SceneSizeError> {
    check_entries("bodies", scene.bodies.len())?;
    check_entries("joints", scene.joints.len())?;
    check_entries("drivers", scene.drivers.len())?;
    check_entries("springs", scene.springs.len())?;
    check_entries("loads", scene.loads.len())?;
    check_entries("events", scene.events.len())?;
    check_entries("outputs", scene.outputs.len())?;
    check_points(scene.bodies.iter().map(|b| b.points.len()).sum())?;
    if let Some(g) = &scene.bond_graph {
        for (key, list) in [
            ("elements", "bond_graph.elements"),
            ("bonds", "bond_graph.bonds"),
        ] {
            if let Some(a) = g.get(key).and_then(|v| v.as_array()) {
                check_entries(list, a.len())?;
            }
        }
    }
    Ok(())
}

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
    magnitudes(&mut p, "gravity", &scene.gravity, MAX_GRAVITY, GRAVITY_WHY);
    if let Err(e) = check_scene_size(scene) {
        // refused at once: nothing else is looked at in a scene this large
        p.push(e.path(), e.to_string());
        return p.list;
    }
    let scene = &Indexed::new(scene);
    let mut body_names = std::collections::HashSet::new();
    for (i, b) in scene.bodies.iter().enumerate() {
        let duplicate = !body_names.insert(b.name.as_str());
        body(&mut p, scene, i, b, duplicate);
    }
    let mut joint_names = std::collections::HashSet::new();
    for (i, j) in scene.joints.iter().enumerate() {
        let path = index("joints", i);
        if !joint_names.insert(j.name.as_str()) {
            p.push(
                field(&path, "name"),
                format!("duplicate joint name '{}'", j.name),
            );
        }
        joint(&mut p, scene, &path, j);
    }
    // spring and load names are what `--set 'springs[NAME]…'` and messages refer to: two
    // entries with one name would make `--set` edit only the first
    let mut spring_names = std::collections::HashSet::new();
    for (i, s) in scene.springs.iter().enumerate() {
        let path = index("springs", i);
        if !spring_names.insert(s.name.as_str()) {
            p.push(
                field(&path, "name"),
                format!(
                    "duplicate spring name '{}' (an unnamed spring i is called 'spring<i>')",
                    s.name
                ),
            );
        }
        attachment(&mut p, scene, &path, &s.bodies, &s.points);
        non_negative(&mut p, &field(&path, "stiffness"), s.stiffness);
        magnitude(
            &mut p,
            &field(&path, "stiffness"),
            s.stiffness,
            MAX_SPRING,
            SPRING_WHY,
        );
        non_negative(&mut p, &field(&path, "damping"), s.damping);
        magnitude(
            &mut p,
            &field(&path, "damping"),
            s.damping,
            MAX_SPRING,
            SPRING_WHY,
        );
        if let Some(l0) = s.rest_length {
            non_negative(&mut p, &field(&path, "rest_length"), l0);
            magnitude(
                &mut p,
                &field(&path, "rest_length"),
                l0,
                MAX_COORDINATE,
                COORDINATE_WHY,
            );
        }
    }
    let mut load_names = std::collections::HashSet::new();
    for (i, l) in scene.loads.iter().enumerate() {
        if !load_names.insert(l.name.as_str()) {
            p.push(
                field(&index("loads", i), "name"),
                format!(
                    "duplicate load name '{}' (an unnamed load i is called 'load<i>')",
                    l.name
                ),
            );
        }
        load(&mut p, scene, &index("loads", i), l);
    }
    solve(&mut p, &scene.solve, length_scale(scene));
    for (i, o) in scene.outputs.iter().enumerate() {
        output(&mut p, scene, &index("outputs", i), o);
    }
    let mut event_names = std::collections::HashSet::new();
    for (i, e) in scene.events.iter().enumerate() {
        let path = index("events", i);
        if e.name.is_empty() {
            p.push(field(&path, "name"), "must not be empty");
        } else if !event_names.insert(e.name.as_str()) {
            p.push(
                field(&path, "name"),
                format!("duplicate event name '{}'", e.name),
            );
        }
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
    super::drivers::validate(&mut p, scene);
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
    let touched: std::collections::HashSet<&str> = scene
        .joints
        .iter()
        .flat_map(|j| j.bodies.iter())
        .chain(scene.springs.iter().flat_map(|s| s.bodies.iter()))
        .map(String::as_str)
        .chain(scene.loads.iter().map(|l| l.body.as_str()))
        .collect();
    scene
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| !touched.contains(b.name.as_str()))
        .map(|(i, b)| {
            Problem::new(
                index("bodies", i),
                format!("'{}' is not connected to anything", b.name),
            )
        })
        .collect()
}

/// A scene with its body and point names in hash maps, so that checking every reference is
/// linear in the scene's size (a name looked up by scanning the bodies or points made 40 000
/// points take seconds, 200 000 bodies minutes).
struct Indexed<'a> {
    scene: &'a Scene,
    body_map: std::collections::HashMap<&'a str, usize>,
    /// The point names of each body, built on first use of that body.
    point_sets:
        std::cell::RefCell<std::collections::HashMap<usize, std::collections::HashSet<&'a str>>>,
}

impl<'a> Indexed<'a> {
    fn new(scene: &'a Scene) -> Self {
        let mut bodies = std::collections::HashMap::with_capacity(scene.bodies.len());
        for (i, b) in scene.bodies.iter().enumerate() {
            // the first of duplicated names, as Scene::body_index finds it
            bodies.entry(b.name.as_str()).or_insert(i);
        }
        Indexed {
            scene,
            body_map: bodies,
            point_sets: Default::default(),
        }
    }

    /// Index of the named body (`None` for ground or an unknown name).
    fn body_index(&self, name: &str) -> Option<usize> {
        self.body_map.get(name).copied()
    }

    /// Whether body `bi` has a point called `name`.
    fn has_point(&self, bi: usize, name: &str) -> bool {
        let body = &self.scene.bodies[bi];
        if body.points.len() < 8 {
            return body.point(name).is_some();
        }
        self.point_sets
            .borrow_mut()
            .entry(bi)
            .or_insert_with(|| body.point_names().collect())
            .contains(name)
    }
}

impl std::ops::Deref for Indexed<'_> {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        self.scene
    }
}

/// The first few of `names`, comma-separated, with how many more there are (a message must
/// not list 40 000 point names).
fn some_names<'n>(mut names: impl Iterator<Item = &'n str>) -> String {
    const SHOWN: usize = 20;
    let shown: Vec<&str> = names.by_ref().take(SHOWN).collect();
    let more = names.count();
    let mut text = shown.join(", ");
    if more > 0 {
        text.push_str(&format!(", … and {more} more"));
    }
    text
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

fn non_negative(p: &mut Problems, path: &str, x: f64) {
    if !(x >= 0.0 && x.is_finite()) {
        p.push(path, format!("must be >= 0 and finite (got {x})"));
    }
}

/// Refuses a finite `x` beyond `±max` at `path` (a magnitude no mechanism has, whose products
/// with the scene's other quantities overflow or leave no digits: [`MAX_COORDINATE`] and the
/// bounds beside it).
fn magnitude(p: &mut Problems, path: &str, x: f64, max: f64, why: &str) {
    if x.is_finite() && x.abs() > max {
        p.push(path, format!("must be within ±{max:e} (got {x:e}): {why}"));
    }
}

/// [`magnitude`] for each component of `v` (`path[k]`).
fn magnitudes(p: &mut Problems, path: &str, v: &[f64], max: f64, why: &str) {
    for (k, x) in v.iter().enumerate() {
        magnitude(p, &index(path, k), *x, max, why);
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

fn body(p: &mut Problems, scene: &Indexed<'_>, i: usize, b: &Body, duplicate: bool) {
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
    } else if b.name.contains('`') {
        p.push(
            &np,
            format!(
                "'{}' must not contain '`' (expressions quote names in backquotes: `left-arm.x`)",
                b.name
            ),
        );
    } else if b.name.contains(',') {
        p.push(&np, comma_in_name(&b.name));
    } else if duplicate {
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
        if name.is_empty() || name.contains('.') || name.contains('`') {
            p.push(
                &path_k,
                "a point name must be non-empty and contain no '.' and no '`'",
            );
        } else if name.contains(',') {
            p.push(&path_k, comma_in_name(name));
        }
        vec_len(p, &path_k, c, dim.coords());
        magnitudes(p, &path_k, c, MAX_COORDINATE, COORDINATE_WHY);
    }
    vec_len(p, &field(&path, "position"), &b.position, dim.coords());
    magnitudes(
        p,
        &field(&path, "position"),
        &b.position,
        MAX_COORDINATE,
        COORDINATE_WHY,
    );
    vec_len(p, &field(&path, "velocity"), &b.velocity, dim.coords());
    magnitudes(
        p,
        &field(&path, "velocity"),
        &b.velocity,
        MAX_SPEED,
        SPEED_WHY,
    );
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
    magnitudes(p, &wp, &b.angular_velocity, MAX_SPEED, SPEED_WHY);
    finite(p, &field(&path, "angle"), b.angle);
    magnitude(p, &field(&path, "angle"), b.angle, MAX_ANGLE, ANGLE_WHY);
    for (k, x) in b.cardan.iter().enumerate() {
        finite(p, &index(&field(&path, "cardan"), k), *x);
    }
    magnitudes(p, &field(&path, "cardan"), &b.cardan, MAX_ANGLE, ANGLE_WHY);
}

/// Checks that `name` is ground or a known body and that `point` exists on it.
fn point_on(
    p: &mut Problems,
    scene: &Indexed<'_>,
    body_path: &str,
    name: &str,
    point_path: &str,
    point: &PointRef,
) {
    let dim = scene.dimension;
    if let PointRef::Coords(c) = point {
        magnitudes(p, point_path, c, MAX_COORDINATE, COORDINATE_WHY);
    }
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
            if !scene.has_point(bi, n) {
                let has = if b.points.is_empty() {
                    "it has no named points".to_string()
                } else {
                    format!("it has: {}", some_names(b.point_names()))
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
    scene: &Indexed<'_>,
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

fn joint(p: &mut Problems, scene: &Indexed<'_>, path: &str, j: &Joint) {
    if j.name.is_empty() {
        p.push(field(path, "name"), "must not be empty");
    } else if j.name.contains('`') {
        p.push(
            field(path, "name"),
            format!(
                "'{}' must not contain '`' (expressions quote names in backquotes)",
                j.name
            ),
        );
    } else if j.name.contains(',') {
        p.push(field(path, "name"), comma_in_name(&j.name));
    }
    attachment(p, scene, path, &j.bodies, &j.points);
    j.kind.validate(p, scene.dimension, path, &j.bodies);
}

fn load(p: &mut Problems, scene: &Indexed<'_>, path: &str, l: &Load) {
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
        LoadValue::Const(v) => {
            vec_len(p, &vp, v, n);
            magnitudes(p, &vp, v, MAX_LOAD, LOAD_WHY);
        }
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
                magnitudes(p, &index(&v_path, k), row, MAX_LOAD, LOAD_WHY);
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
    if t0.is_finite() && s.t_end.is_finite() && !span.is_finite() {
        p.push(
            "solve.t_end",
            format!(
                "t_end - t_start = {:e} - ({t0:e}) overflows to {span}: the time span must be finite",
                s.t_end
            ),
        );
    }
    if span.is_finite() && span > 0.0 && span < MIN_SPAN {
        p.push(
            "solve.t_end",
            format!(
                "t_end - t_start = {span:e} s is shorter than {MIN_SPAN:e} s: the solver's step sizes underflow below it (rule: t_end - t_start >= 1e-100 s)"
            ),
        );
    }
    // the output times must be told apart in floating point: t + h must differ from t
    let t_max = t0.abs().max(s.t_end.abs());
    if t_max.is_finite() && span.is_finite() && span > 0.0 {
        let h = match (s.output_step, &s.output_times) {
            (Some(h), _) => h,
            (None, Some(_)) => span,
            (None, None) => span / SolveSettings::DEFAULT_OUTPUT_INTERVALS as f64,
        };
        if h.is_finite() && h > 0.0 && h <= MIN_RELATIVE_STEP * t_max {
            let at = if s.output_step.is_some() {
                "solve.output_step"
            } else {
                "solve.t_end"
            };
            p.push(
                at,
                format!(
                    "an output interval of {h:e} s is below the resolution of doubles at t = {t_max:e} (t + h must differ from t; the interval must exceed {:e} s there): shift the times toward 0 with solve.t_start",
                    MIN_RELATIVE_STEP * t_max
                ),
            );
        }
    }
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
    if let Some(n) = s.max_steps {
        bound(p, "solve.max_steps", check_max_steps(n));
    }
    if let Some(w) = s.max_wall_seconds {
        bound(p, "solve.max_wall_seconds", check_wall_seconds(w));
    }
}

/// Smallest output interval relative to the largest time of the run: 2⁶ units in the last
/// place, so that `t + h` is a different double from `t` with room for rounding.
pub const MIN_RELATIVE_STEP: f64 = 64.0 * f64::EPSILON;

fn output(p: &mut Problems, scene: &Indexed<'_>, path: &str, o: &str) {
    match o.split_once('.') {
        None => {
            if !SCALAR_OUTPUTS.contains(&o) {
                p.push(
                    path,
                    format!(
                        "unknown output '{o}'{} (expected body.point, body.column or one of: {})",
                        super::fields::did_you_mean_note(o, SCALAR_OUTPUTS.iter().copied()),
                        SCALAR_OUTPUTS.join(", ")
                    ),
                );
            }
        }
        // a raw graph's outputs name its own columns (checked against the graph)
        Some(_) if scene.bond_graph.is_some() => {}
        Some((b, rest)) => {
            let Some(bi) = scene.body_index(b) else {
                let note = super::fields::did_you_mean_note(
                    b,
                    scene.bodies.iter().map(|x| x.name.as_str()),
                );
                p.push(path, format!("unknown body '{b}'{note}"));
                return;
            };
            let body = &scene.bodies[bi];
            // `b.P.x`, `b.P.vx`, … : one coordinate or velocity component of a named point
            if let Some((pt, comp)) = rest.split_once('.') {
                let comps: &[&str] = match scene.dimension {
                    Dimension::Planar => &["x", "y", "vx", "vy"],
                    Dimension::Spatial => &["x", "y", "z", "vx", "vy", "vz"],
                };
                if !scene.has_point(bi, pt) {
                    p.push(
                        path,
                        format!(
                            "body '{b}' has no point '{pt}'{} (it has: {})",
                            super::fields::did_you_mean_note(pt, body.point_names()),
                            some_names(body.point_names())
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
            if !scene.has_point(bi, rest) && !BODY_COLUMNS.contains(&rest) {
                p.push(
                    path,
                    format!(
                        "body '{b}' has no point '{rest}'{} (it has: {}; nor is it a body column: {})",
                        super::fields::did_you_mean_note(
                            rest,
                            body.point_names().chain(BODY_COLUMNS.iter().copied())
                        ),
                        some_names(body.point_names()),
                        BODY_COLUMNS.join(", ")
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

/// Largest coordinate (m) of a body's position, a point, a ground attachment or a rest length:
/// a mechanism of 1e12 m (seven times the Earth–Sun distance) is no mechanism, and beyond it a
/// double keeps fewer than 4 digits of a millimetre (`1e12 · 2.2e-16 = 2.2e-4 m`), and the
/// products with speeds, masses and loads head for overflow (issue 38: a position of 1e300
/// was solved, with 1e300 in the CSV).
pub const MAX_COORDINATE: f64 = 1e12;
const COORDINATE_WHY: &str = "a coordinate beyond 1e12 m leaves no digits for the mechanism's own motion, and its products with the other quantities overflow (rule: |x| <= 1e12 m)";
/// Largest angle (rad) of a body's `angle` or `cardan` angles: 1e6 rad is 160 000 turns; beyond
/// it `sin` and `cos` of the angle keep fewer than 10 digits (`1e6 · 2.2e-16 = 2.2e-10 rad`).
pub const MAX_ANGLE: f64 = 1e6;
const ANGLE_WHY: &str = "an angle beyond 1e6 rad (160 000 turns) loses its digits in sin and cos; give it modulo 2π (rule: |angle| <= 1e6 rad)";
/// Largest initial speed (m/s) or angular speed (rad/s) component: `v²` and `ω² r` of larger
/// speeds, in the constraint accelerations and the energies, overflow with the masses allowed
/// (issue 38: a velocity of 1e200 failed as "non-finite value in the constraint acceleration
/// terms").
pub const MAX_SPEED: f64 = 1e12;
const SPEED_WHY: &str = "a speed beyond 1e12 m/s (or rad/s) makes v² and ω²·r overflow in the constraint accelerations and the energies (rule: |v| <= 1e12)";
/// Largest gravity component (m/s²): `m g` and `m g y` overflow beyond it with the masses and
/// coordinates allowed (issue 38: gravity 1e308 failed as "the residual evaluates to -inf").
pub const MAX_GRAVITY: f64 = 1e12;
const GRAVITY_WHY: &str = "gravity beyond 1e12 m/s² makes the weights m·g and the potential energy m·g·y overflow (rule: |g| <= 1e12 m/s²)";
/// Largest spring stiffness (N/m) or damping (N·s/m), as [`MAX_MASS`]: `k x²`, `k/m` overflow
/// beyond it (issue 38: a stiffness of 1e300 failed as an IDA failure handed to the GGL).
pub const MAX_SPRING: f64 = 1e100;
const SPRING_WHY: &str = "a spring stiffer (or a damper stronger) than 1e100 makes k·x² and k/m overflow (rule: 0 <= k, c <= 1e100)";
/// Largest load component (N or N·m), constant or tabulated, as [`MAX_MASS`] (issue 38: a load
/// table of 1e308 failed as "`y0[6]` is not finite").
pub const MAX_LOAD: f64 = 1e100;
const LOAD_WHY: &str = "a load beyond 1e100 N (N·m) overflows in the accelerations and the work it does (rule: |F| <= 1e100)";
/// Shortest time span `t_end − t_start` (s): below about 1e-160 s the solver's step-size
/// arithmetic underflows and IDA refuses the first step (issue 38: `t_end` 1e-300 failed as
/// "IDA_ILL_INPUT").
pub const MIN_SPAN: f64 = 1e-100;

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
/// with the joint forces known ([`crate::solve::formulation::decoupled::prestress_warning`]).
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

/// A wall-clock budget (`solve.max_wall_seconds`, `--max-wall-seconds`, the service's
/// `?max_wall_seconds=` and `--max-solve-seconds`, s): finite, `> 0`, at most
/// [`MAX_WALL_SECONDS`] (1e9 s). The budget becomes a [`std::time::Duration`] through
/// [`wall_clock`].
pub fn check_wall_seconds(value: f64) -> Result<(), BoundError> {
    finite_positive(value)?;
    if value > MAX_WALL_SECONDS {
        return Err(BoundError::TooLarge {
            value,
            max: MAX_WALL_SECONDS,
            why: "a longer budget is no budget (leave the setting out for none)",
        });
    }
    Ok(())
}

/// Largest step budget (`solve.max_steps`, `--max-steps`, the service's `?max_steps=`): 1e15
/// internal steps, some 30 years at a microsecond per step. A larger number (2⁶⁴ − 1, the
/// largest a JSON reader may hand over) is no budget, which is said by leaving it out.
pub const MAX_STEPS: f64 = 1e15;

/// A step budget: a whole number `>= 1`, at most [`MAX_STEPS`].
pub fn check_max_steps(value: u64) -> Result<(), BoundError> {
    let v = value as f64;
    if value == 0 {
        return Err(BoundError::NotPositive { value: v });
    }
    if v > MAX_STEPS {
        return Err(BoundError::TooLarge {
            value: v,
            max: MAX_STEPS,
            why: "a larger budget is no budget, some 30 years of steps (leave max_steps out for none)",
        });
    }
    Ok(())
}

/// A grace period (the service's `--shutdown-grace`, s): finite, `>= 0`, at most
/// [`MAX_WALL_SECONDS`].
pub fn check_grace_seconds(value: f64) -> Result<(), BoundError> {
    if !(value.is_finite() && value >= 0.0) {
        return Err(BoundError::Negative { value });
    }
    if value > MAX_WALL_SECONDS {
        return Err(BoundError::TooLarge {
            value,
            max: MAX_WALL_SECONDS,
            why: "a longer grace period never ends",
        });
    }
    Ok(())
}

/// Seconds as a [`std::time::Duration`], for a number already checked by
/// [`check_wall_seconds`] or [`check_grace_seconds`]: never panics (negative, NaN and
/// non-finite numbers give an error, too large ones saturate at [`MAX_WALL_SECONDS`]).
pub fn wall_clock(seconds: f64) -> Result<std::time::Duration, BoundError> {
    if !(seconds.is_finite() && seconds >= 0.0) {
        return Err(BoundError::Negative { value: seconds });
    }
    std::time::Duration::try_from_secs_f64(seconds.min(MAX_WALL_SECONDS))
        .map_err(|_| BoundError::Negative { value: seconds })
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
