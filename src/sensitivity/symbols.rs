//! The mechanism's equations with the run's parameters as symbols: `M(p) v' = Q(t, q, v; p) −
//! G_v(q; p)ᵀ λ`, `g(q; p) = 0`, `q' = K(q; p) v` in the system's own expression graph, and the
//! derivatives `∂q₀/∂p`, `∂v₀/∂p` of the scene's initial coordinates and velocities (before
//! the projection onto the joints).
//!
//! The scene's numbers reach the bond graph as its elements' constants (an inertia's mass, a
//! spring's compliance `1/k`, a damper's `c`, a gravity source's `−m g`) and as the numbers in
//! its expressions (a transformer's modulus, a joint's closure: the geometry). The scene is
//! built at three values of each parameter; a constant or a number that changes is an affine
//! (`θ = a + b p`: masses, dampings, loads, gravity, points) or reciprocal (`θ = c / p`: a
//! compliance) function of it, checked exactly at the three values (anything else is refused
//! naming the element). Those constants and numbers are written as expressions of the
//! parameter's symbol `p_k` (a variable slot after every unknown), the bond graph is read again
//! into the same expression graph, and the formulation's residual is built from it with the
//! same code as the run's ([`crate::solve::formulation::index1`]): `∂F/∂p_k` is then one
//! symbolic derivative of the same expressions, evaluated at the scene's values.

use crate::bond::mechanics::read_mechanics_with_names;
use crate::bond::model::{BondGraph, Parameter};
use crate::expr::{Expr, ExprGraph};
use crate::mech::MultibodySystem;
use crate::scene::Scene;

use super::{SceneParameter, SensitivityError};

/// The variable slot of parameter `k`'s symbol (after any formulation's `[t, y, y']`; every
/// symbol is replaced by its value before anything is compiled).
pub fn parameter_slot(k: usize) -> u32 {
    u32::MAX - 1 - k as u32
}

/// Parameter `k`'s name in the bond graph's expressions.
fn parameter_name(k: usize) -> String {
    format!("sensitivity_parameter_{k}")
}

/// Relative agreement of the exact affine / reciprocal checks at the three values.
const FORM_TOLERANCE: f64 = 1e-12;

/// The mechanism with its parameters as symbols (see the module documentation).
#[derive(Clone, Debug)]
pub struct SymbolicSystem {
    /// The system: forces, inertias (`mass_symbols`), closures, flows and kinematics over
    /// `[t, q, v]` and the parameters' slots ([`parameter_slot`]).
    pub sys: MultibodySystem,
    /// The parameters, in order.
    pub params: Vec<SceneParameter>,
    /// `∂q₀/∂p_k` of the scene's initial coordinates, per parameter.
    pub dq0: Vec<Vec<f64>>,
    /// `∂v₀/∂p_k` of the scene's initial velocities, per parameter.
    pub dv0: Vec<Vec<f64>>,
    /// Per parameter: the output columns whose expression depends on it (not only through the
    /// state); their sensitivities are not written.
    pub explicit_columns: Vec<Vec<String>>,
    /// Per parameter: whether anything of the mechanism changes with it.
    pub enters: Vec<bool>,
}

impl SymbolicSystem {
    /// `[(slot, value)]` of every parameter: substituted after differentiating.
    pub fn values(&self, g: &mut ExprGraph) -> Vec<(u32, Expr)> {
        self.params
            .iter()
            .enumerate()
            .map(|(k, p)| (parameter_slot(k), g.constant(p.value)))
            .collect()
    }

    /// `∂e/∂p_k` at the parameters' values, for every `k` (expressions over the other slots).
    pub fn derivatives(&mut self, exprs: &[Expr]) -> Vec<Vec<Expr>> {
        let g = &mut self.sys.graph;
        let values: Vec<(u32, Expr)> = self
            .params
            .iter()
            .enumerate()
            .map(|(k, p)| (parameter_slot(k), g.constant(p.value)))
            .collect();
        (0..self.params.len())
            .map(|k| {
                let d: Vec<Expr> = exprs
                    .iter()
                    .map(|&e| g.diff(e, parameter_slot(k)))
                    .collect();
                g.substitute_all(&d, &values)
            })
            .collect()
    }
}

impl crate::solve::formulation::ParameterSymbols for SymbolicSystem {
    fn system(&mut self) -> &mut MultibodySystem {
        &mut self.sys
    }

    fn derivatives(&mut self, exprs: &[Expr]) -> Vec<Vec<Expr>> {
        SymbolicSystem::derivatives(self, exprs)
    }
}

/// The value's form as a function of the parameter, from three exact samples.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Form {
    /// `a + b p`.
    Affine(f64, f64),
    /// `c / p`.
    Reciprocal(f64),
}

impl Form {
    fn text(self, name: &str) -> String {
        match self {
            Form::Affine(a, b) => format!("(({a:?}) + ({b:?})*{name})"),
            Form::Reciprocal(c) => format!("(({c:?})/{name})"),
        }
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= FORM_TOLERANCE * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

/// The affine or reciprocal function through `(p_k, θ_k)`, `None` if neither fits all three.
fn form(p: [f64; 3], th: [f64; 3]) -> Option<Form> {
    let b = (th[2] - th[1]) / (p[2] - p[1]);
    let a = th[1] - b * p[1];
    if close(a + b * p[0], th[0]) && close(a + b * p[2], th[2]) {
        return Some(Form::Affine(a, b));
    }
    let c = th[1] * p[1];
    if p.iter().all(|&x| x != 0.0) && close(th[0] * p[0], c) && close(th[2] * p[2], c) {
        return Some(Form::Reciprocal(c));
    }
    None
}

/// `dθ/dp` of an affine function (`None`: not affine).
fn affine_slope(p: [f64; 3], th: [f64; 3]) -> Option<f64> {
    if th[0] == th[1] && th[1] == th[2] {
        return Some(0.0);
    }
    match form(p, th) {
        Some(Form::Affine(_, b)) => Some(b),
        _ => None,
    }
}

/// A text split into numbers and the rest (names, backquoted names, operators), so that two
/// texts of the same expression at two parameter values can be compared number by number.
fn tokens(s: &str) -> Vec<(bool, &str)> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let mut rest = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'`' {
            i += 1;
            while i < b.len() && b[i] != b'`' {
                i += 1;
            }
            i += 1;
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] == b'.') {
                i += 1;
            }
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            if rest < i {
                out.push((false, &s[rest..i]));
            }
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                if j < b.len() && b[j].is_ascii_digit() {
                    i = j;
                    while i < b.len() && b[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            out.push((true, &s[start..i]));
            rest = i;
        } else {
            i += 1;
        }
    }
    if rest < b.len() {
        out.push((false, &s[rest..]));
    }
    out
}

/// The text `t0` with every number that differs between `t0`, `t1`, `t2` (the texts at the
/// three values `p`) written as its affine or reciprocal function of `name`; `Err` naming
/// `what` where the texts differ otherwise or a number is neither.
fn symbolic_text(
    [t0, t1, t2]: [&str; 3],
    p: [f64; 3],
    name: &str,
    what: &str,
) -> Result<Option<String>, String> {
    if t0 == t1 && t0 == t2 {
        return Ok(None);
    }
    let (a, b, c) = (tokens(t0), tokens(t1), tokens(t2));
    if a.len() != b.len() || a.len() != c.len() {
        return Err(format!("{what} changes its form"));
    }
    let mut out = String::with_capacity(t0.len() + 32);
    for ((x, y), z) in a.iter().zip(&b).zip(&c) {
        match (x, y, z) {
            ((true, u), (true, v), (true, w)) if !(u == v && u == w) => {
                let th = [u, v, w].map(|s| s.parse::<f64>().unwrap_or(f64::NAN));
                let f = form(p, th).ok_or_else(|| {
                    format!("{what} depends on it neither affinely nor reciprocally")
                })?;
                out.push_str(&f.text(name));
            }
            ((nx, u), (ny, v), (nz, w)) if nx == ny && ny == nz && u == v && u == w => {
                out.push_str(u)
            }
            _ => return Err(format!("{what} changes its form")),
        }
    }
    Ok(Some(out))
}

/// The system of `scene` (built at the parameters' values) with the parameters as symbols.
pub fn derive(
    scene: &Scene,
    sys: &MultibodySystem,
    params: &[SceneParameter],
) -> Result<SymbolicSystem, SensitivityError> {
    let Some(bg0) = sys.bond_graph.clone() else {
        return Err(SensitivityError::Scene(
            "sensitivities need the equations read off the mechanism's bond graph (planar scenes in the non-rotating frame); this scene's are assembled from the bodies".into(),
        ));
    };
    let (nq, nv) = (sys.nq(), sys.nv());
    let mut graph: BondGraph = (*bg0).clone();
    let mut changed_by: Vec<Option<usize>> = vec![None; graph.elements.len()];
    let mut closure_by: Vec<Option<usize>> = vec![None; graph.constraint_junctions.len()];
    let mut mass_forms: Vec<Option<(usize, f64, f64)>> = vec![None; nv];
    let mut out = SymbolicSystem {
        sys: sys.clone(),
        params: params.to_vec(),
        dq0: Vec::new(),
        dv0: Vec::new(),
        explicit_columns: Vec::new(),
        enters: Vec::new(),
    };
    for (k, param) in params.iter().enumerate() {
        let unsupported = |reason: String| SensitivityError::Unsupported {
            path: param.path.clone(),
            reason,
        };
        let p0 = param.value;
        let d = if p0 != 0.0 { 0.25 * p0.abs() } else { 0.25 };
        let ps = [p0, p0 + d, p0 + 2.0 * d];
        let build = |v: f64| -> Result<MultibodySystem, SensitivityError> {
            let s = param.scene_at(scene, v)?;
            crate::mech::build(&s).map_err(|e| {
                unsupported(format!("the scene with the value {v} cannot be built: {e}"))
            })
        };
        let sys1 = build(ps[1])?;
        let sys2 = build(ps[2])?;
        let (bg1, bg2) = match (&sys1.bond_graph, &sys2.bond_graph) {
            (Some(a), Some(b)) => (a.clone(), b.clone()),
            _ => return Err(unsupported("the changed scene has no bond graph".into())),
        };
        if sys1.nq() != nq || sys1.nv() != nv || sys1.nc() != sys.nc() {
            return Err(unsupported("it changes the mechanism's unknowns".into()));
        }
        same_elements(&bg0, &bg1)
            .and_then(|_| same_elements(&bg0, &bg2))
            .map_err(&unsupported)?;
        let name = parameter_name(k);
        let mut enters = false;
        let claim = |slot: &mut Option<usize>, what: &str| -> Result<(), SensitivityError> {
            match slot {
                Some(other) if *other != k => Err(unsupported(format!(
                    "{what} depends on it and on --param {} too; give one of them",
                    params[*other].path
                ))),
                _ => {
                    *slot = Some(k);
                    Ok(())
                }
            }
        };
        for (i, e0) in bg0.elements.iter().enumerate() {
            let (e1, e2) = (&bg1.elements[i], &bg2.elements[i]);
            if e0.parameter == e1.parameter && e0.parameter == e2.parameter {
                continue;
            }
            let what = format!("element '{}'", e0.name);
            let text = match (&e0.parameter, &e1.parameter, &e2.parameter) {
                (
                    Some(Parameter::Const(a)),
                    Some(Parameter::Const(b)),
                    Some(Parameter::Const(c)),
                ) => form(ps, [*a, *b, *c])
                    .ok_or_else(|| {
                        unsupported(format!(
                            "{what} depends on it neither affinely nor reciprocally"
                        ))
                    })?
                    .text(&name),
                (Some(Parameter::Expr(a)), Some(Parameter::Expr(b)), Some(Parameter::Expr(c))) => {
                    symbolic_text([a, b, c], ps, &name, &what)
                        .map_err(&unsupported)?
                        .unwrap_or_else(|| a.clone())
                }
                _ => return Err(unsupported(format!("{what} changes its kind of value"))),
            };
            enters = true;
            claim(&mut changed_by[i], &what)?;
            if e0.kind != crate::bond::model::ElementKind::I {
                graph.elements[i].parameter = Some(Parameter::Expr(text));
            }
        }
        for (i, c0) in bg0.constraint_junctions.iter().enumerate() {
            let (c1, c2) = (&bg1.constraint_junctions[i], &bg2.constraint_junctions[i]);
            let what = format!("the closure of joint '{}' ({})", c0.joint, c0.direction);
            match (&c0.closure, &c1.closure, &c2.closure) {
                (Some(a), Some(b), Some(c)) => {
                    if let Some(t) =
                        symbolic_text([a, b, c], ps, &name, &what).map_err(&unsupported)?
                    {
                        enters = true;
                        claim(&mut closure_by[i], &what)?;
                        graph.constraint_junctions[i].closure = Some(t);
                    }
                }
                (a, b, c) if a == b && a == c => {}
                _ => return Err(unsupported(format!("{what} changes"))),
            }
        }
        let slope = |what: &str, a: f64, b: f64, c: f64| {
            affine_slope(ps, [a, b, c])
                .ok_or_else(|| unsupported(format!("{what} depends on it non-affinely")))
        };
        for (j, form) in mass_forms.iter_mut().enumerate() {
            let b = slope(
                &format!("the inertia of '{}'", sys.velocities[j].name),
                sys.mass[j],
                sys1.mass[j],
                sys2.mass[j],
            )?;
            if b != 0.0 {
                if let Some((other, _, _)) = *form {
                    return Err(unsupported(format!(
                        "the inertia of '{}' depends on it and on --param {} too",
                        sys.velocities[j].name, params[other].path
                    )));
                }
                *form = Some((k, sys.mass[j] - b * p0, b));
                enters = true;
            }
        }
        let mut dq0 = Vec::with_capacity(nq);
        for i in 0..nq {
            dq0.push(slope(
                &format!("the initial '{}'", sys.coords[i].name),
                sys.coords[i].initial,
                sys1.coords[i].initial,
                sys2.coords[i].initial,
            )?);
        }
        let mut dv0 = Vec::with_capacity(nv);
        for j in 0..nv {
            dv0.push(slope(
                &format!("the initial '{}'", sys.velocities[j].name),
                sys.velocities[j].initial,
                sys1.velocities[j].initial,
                sys2.velocities[j].initial,
            )?);
        }
        let explicit = explicit_columns(sys, &sys1);
        enters |= dq0.iter().chain(&dv0).any(|&d| d != 0.0) || !explicit.is_empty();
        out.dq0.push(dq0);
        out.dv0.push(dv0);
        out.explicit_columns.push(explicit);
        out.enters.push(enters);
    }
    // the bond graph read again with the symbols, into the system's graph
    let g = &mut out.sys.graph;
    let names: Vec<(String, u32, f64)> = params
        .iter()
        .enumerate()
        .map(|(k, p)| (parameter_name(k), parameter_slot(k), p.value))
        .collect();
    let eqs = read_mechanics_with_names(&graph, std::mem::take(g), &names).map_err(|e| {
        SensitivityError::Scene(format!(
            "the bond graph cannot be read with the parameters as symbols: {e}"
        ))
    })?;
    let s = &mut out.sys;
    s.graph = eqs.graph;
    if eqs.forces.len() != nv || eqs.kinematics.len() != nq {
        return Err(SensitivityError::Scene(
            "the bond graph read with the parameters as symbols has other unknowns".into(),
        ));
    }
    s.forces = eqs.forces;
    s.kinematics = eqs.kinematics;
    let mut closures = Vec::with_capacity(s.rows.len());
    let mut flows = Vec::with_capacity(s.rows.len());
    for row in &s.rows {
        let r = eqs
            .rows
            .iter()
            .find(|r| r.joint == row.joint && r.direction == row.direction)
            .and_then(|r| Some((r.closure?, r.flow)))
            .ok_or_else(|| {
                SensitivityError::Scene(format!(
                    "the joint row {}.{} is missing from the bond graph read with the parameters as symbols",
                    row.joint, row.direction
                ))
            })?;
        closures.push(r.0);
        flows.push(r.1);
    }
    s.constraints = closures;
    s.flow_rows = flows;
    s.mass_symbols = (0..nv)
        .map(|j| match mass_forms[j] {
            Some((k, a, b)) => {
                let p = s.graph.var(parameter_slot(k));
                let bp = s.graph.scale(b, p);
                let a = s.graph.constant(a);
                s.graph.add(a, bp)
            }
            None => s.graph.constant(s.mass[j]),
        })
        .collect();
    Ok(out)
}

/// `Ok` when the two bond graphs have the same elements (names, kinds), bonds and joints; else
/// what differs.
fn same_elements(a: &BondGraph, b: &BondGraph) -> Result<(), String> {
    let differ = |what: String| {
        format!("it changes the mechanism's {what}; sensitivities need the same bond graph at nearby values")
    };
    if a.elements.len() != b.elements.len() || a.bonds.len() != b.bonds.len() {
        return Err(differ("bond graph".into()));
    }
    for (x, y) in a.elements.iter().zip(&b.elements) {
        if x.name != y.name || x.kind != y.kind {
            return Err(differ(format!("element '{}'", x.name)));
        }
    }
    if a.constraint_junctions.len() != b.constraint_junctions.len() {
        return Err(differ("joints".into()));
    }
    Ok(())
}

/// The output columns whose value at one state differs between the systems at two values of
/// the parameter: they depend on it explicitly (an energy, a point's position).
fn explicit_columns(sys0: &MultibodySystem, sys1: &MultibodySystem) -> Vec<String> {
    let n = 1 + sys0.nq() + sys0.nv();
    // a fixed state away from any symmetric configuration
    let vars: Vec<f64> = (0..n).map(|i| 0.37 + 0.113 * i as f64).collect();
    sys0.outputs
        .iter()
        .zip(&sys1.outputs)
        .filter(|(a, b)| {
            let (x, y) = (
                sys0.graph.eval(a.expr, &vars),
                sys1.graph.eval(b.expr, &vars),
            );
            a.name != b.name || !(x == y || (x.is_nan() && y.is_nan()))
        })
        .map(|(a, _)| a.name.clone())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_that_change_become_functions_of_the_symbol() {
        let p = [1.0, 1.25, 1.5];
        let t = symbolic_text(
            [
                "x_a.b - 0.5*sin(q2) + 1e-3",
                "x_a.b - 0.625*sin(q2) + 1e-3",
                "x_a.b - 0.75*sin(q2) + 1e-3",
            ],
            p,
            "s",
            "w",
        )
        .unwrap()
        .unwrap();
        assert_eq!(t, "x_a.b - ((0.0) + (0.5)*s)*sin(q2) + 1e-3");
        assert!(symbolic_text(["a+1", "a+2", "b+3"], p, "s", "w").is_err());
        assert_eq!(form(p, [1.0, 0.8, 1.0 / 1.5]), Some(Form::Reciprocal(1.0)));
        assert!(form(p, [1.0, 1.5625, 2.25]).is_none());
    }
}
