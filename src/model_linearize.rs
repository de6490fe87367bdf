//! Linearization about an operating point ([`Model::linearize`]): the linear model `ẋ = A x + B u`, `y = C x + D u`
//! in the chapter's states, its modes and its frequency response.
//!
//! The state `x = [q_I, v_I]` is the partition's: the integral-causality inertias' flows `v_I`
//! and the displacements `q_I` they carry (the ODE states of the partitioned formulation,
//! [`crate::solve::formulation::partitioned`]), chosen by the causality at the operating point. Every other
//! unknown `w = [q_D, v_D, v', λ]` is fixed by `x`, the inputs `u` and `t` through
//!
//! ```text
//!   E(z, u) = [ g(q, t)                      ]  = 0     the joints and drivers (position level)
//!             [ G_v(q) v + b(q, t)           ]          (velocity level: the junctions' flows)
//!             [ M v' − Q(t, q, v, u) + G_vᵀ λ ]          the inertias' effort balance
//!             [ G_v(q) v' + γ(t, q, v)        ]          (acceleration level)
//! ```
//!
//! with `z = [q, v, v', λ]`, and the state's rate is `f(z) = [(K(q) v)_I, v'_I]`. The implicit
//! function theorem gives the exact derivatives of the dependent unknowns,
//! `∂w/∂x = −E_w⁻¹ E_x`, `∂w/∂u = −E_w⁻¹ E_u` (`E_w` is block triangular: `G_q[:, D]`,
//! `G_v[:, D]` and the saddle matrix `[M G_vᵀ; G_v 0]`, regular wherever the partition and the
//! masses are), so
//!
//! ```text
//!   A = f_z Z_x,  B = f_z Z_u,  C = y_z Z_x,  D = y_z Z_u,
//!   Z_x = ∂z/∂x = [I on x; ∂w/∂x],  Z_u = ∂z/∂u = [0 on x; ∂w/∂u].
//! ```
//!
//! Every entry of `E_z`, `f_z` and `y_z` is a symbolic derivative of the expression graph
//! (no finite differences): `∂(G_vᵀλ)/∂q` is the geometric stiffness of the joints' forces,
//! `∂γ/∂q`, `∂γ/∂v` the curvature of the joints along the motion (zero at rest), so the
//! model is the local linearization at any state, not only at a static equilibrium. At a
//! static equilibrium (`v = 0`, `v' = 0`) it reduces to `A = [[0, I], [−M_r⁻¹K_r, −M_r⁻¹D_r]]`
//! with `M_r = Tᵀ M T`, `K_r = −Tᵀ ∂(Q − G_vᵀλ)/∂q T`, `D_r = −Tᵀ ∂Q/∂v T` and
//! `T = [I; −G_D⁻¹ G_I]`.
//!
//! Spatial rigid bodies: their Euler parameters `e0…e3` (four coordinates, three degrees of
//! freedom) and body-frame `ω` are replaced by a rotation-vector chart about the operating point
//! and the space-frame angular velocity ([`chart`]): `E_z`, `f_z`, `y_z` above are chained
//! through `∂z/∂z̃` at the operating point, and the partition is chosen in the chart.
//!
//! Inputs enter the loads only (scene `"inputs"`, §22); `∂Q/∂u_k` is exact: the scene is built
//! once more with the input replaced by `u_k⁰ + (t − t*)`, whose `∂Q/∂t` at `t*` is
//! `∂Q/∂t + ∂Q/∂u_k` (both symbolic derivatives), less the scene's own `∂Q/∂t`.

use nalgebra::{DMatrix, DVector};

use crate::analysis::linear_model::{
    eigenvalues_of, modes_of, LinearModel, LinearizeError, LinearizeOptions, OperatingPoint,
    AT_REST,
};
use crate::dae::ConstraintExprs;
use crate::error::{Error, Result};
use crate::expr::{Expr, Tape};
use crate::mech::MultibodySystem;
use crate::model::Model;
use crate::partition::PartitionPolicy;
use crate::partition::{dependent_condition, select_dependent};
use crate::scene::Scene;
use crate::solve::formulation::PartitionedSystem;

mod chart;

/// The linear model of `scene` about `options.at` (see the module documentation).
///
/// ```
/// # fn main() -> bondmech::Result<()> {
/// use bondmech::{linearize, LinearizeOptions};
/// // a uniform bar (1 kg, 1 m) on a pin at its end O, started 0.4 rad off hanging
/// let scene = bondmech::Scene::from_json_str(r#"{
///   "gravity": [0, -9.81],
///   "bodies": [{"name": "bar", "mass": 1, "inertia": 0.08333333333333333,
///               "points": {"O": [-0.5, 0], "A": [0.5, 0]},
///               "position": [0.1947, -0.4605], "angle": -1.1708}],
///   "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
///               "points": [[0, 0], "O"]}],
///   "solve": {"t_end": 1}}"#)?;
/// let lin = linearize(&scene, &LinearizeOptions::default())?;
/// assert_eq!(lin.states, ["bar.angle", "bar.omega"]);
/// // a uniform bar of length 1 on a pin at its end: ω² = m g (L/2) / (m L²/3)
/// let w = (9.81f64 * 0.5 / (1.0 / 3.0)).sqrt();
/// assert!((lin.modes[0].omega_n - w).abs() < 1e-9 * w);
/// # Ok(()) }
/// ```
pub fn linearize(scene: &Scene, options: &LinearizeOptions) -> Result<LinearModel> {
    let model = Model::new(scene)?;
    let clock = cpu_time::ThreadTime::now();
    let mut lm = linearize_model(&model, scene, options)?;
    lm.cpu_seconds = clock.elapsed().as_secs_f64();
    Ok(lm)
}

/// [`linearize`] of the built `model`, without its clock.
fn linearize_model(
    model: &Model,
    scene: &Scene,
    options: &LinearizeOptions,
) -> Result<LinearModel> {
    let sys0 = model.mechanism().ok_or(LinearizeError::RawGraph)?;
    for u in &scene.inputs {
        for (i, d) in scene.drivers.iter().enumerate() {
            if crate::scene::inputs::replace_name(&d.value, &u.name, "(0)") != d.value {
                return Err(LinearizeError::InputInDriver {
                    input: u.name.clone(),
                    driver: i,
                    name: d.name.clone(),
                }
                .into());
            }
        }
    }
    let (nq, nv, nc) = (sys0.nq(), sys0.nv(), sys0.nc());
    let t_start = scene.solve.t_start;
    let mut sys = sys0.clone();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = crate::dae::MechanicsTapes::new(&mut sys, &c, None);

    // the operating point (t, q, v)
    let (t, x) = operating_point(model, sys0, &tapes, options.at, t_start)?;
    let singular = |why: String| Error::from(LinearizeError::Singular { t, why });

    // accelerations and multipliers there: [M G_vᵀ; G_v 0][v'; λ] = [Q; −γ]
    let (acc, lambda) = accelerations_and_multipliers(sys0, &tapes, t, &x)?;

    // the spatial bodies' attitudes in a three-angle chart about the operating point
    // (chart::Chart), and the partition at the operating point
    let chart = chart::Chart::new(sys0, &x, &acc);
    let (part, notes, states) = match &chart {
        Some(ch) => {
            let part = chart_partition(sys0, ch, options.states.as_deref(), t, &x)?;
            let names = ch.state_names(&part);
            (part, Vec::new(), names)
        }
        None => {
            let (part, notes) = choose_partition(sys0, options.states.as_deref(), t_start, t, &x)?;
            let names = part.state_names(sys0);
            (part, notes, names)
        }
    };

    // symbolic E(z), f(z), y(z) and their derivatives by z = [q, v, v', λ]
    let nz = nq + 2 * nv + nc;
    let a_slot = |j: usize| (1 + nq + nv + j) as u32;
    let l_slot = |i: usize| (1 + nq + 2 * nv + i) as u32;
    let outputs = resolve_outputs(sys0, &mut sys.graph, &states, &options.outputs, l_slot(0))?;
    let g = &mut sys.graph;
    let mut e_rows: Vec<Expr> = c.g.clone();
    e_rows.extend(c.gvv.iter().copied());
    for j in 0..nv {
        let m = g.constant(sys.mass[j]);
        let aj = g.var(a_slot(j));
        let ma = g.mul(m, aj);
        e_rows.push(c.effort_row(g, (j, sys.forces[j]), &[ma], l_slot));
    }
    for i in 0..nc {
        e_rows.push(c.acceleration_row(g, i, a_slot));
    }
    let y_exprs: Vec<Option<Expr>> = outputs.iter().map(|o| o.1).collect();
    // the Jacobians' entries, row by row: (block, row, z index, expression)
    let mut entries: Vec<(usize, usize, usize, Expr)> = Vec::new();
    let mut jac = |g: &mut crate::expr::ExprGraph, block: usize, r: usize, e: Expr| {
        for s in g.vars(e) {
            if s >= 1 && (s as usize) <= nz {
                let d = g.diff(e, s);
                if !g.is_zero(d) {
                    entries.push((block, r, s as usize - 1, d));
                }
            }
        }
    };
    for (r, &e) in e_rows.iter().enumerate() {
        jac(g, 0, r, e);
    }
    for (r, &e) in sys.kinematics.iter().enumerate() {
        jac(g, 1, r, e);
    }
    for (r, e) in y_exprs.iter().enumerate() {
        if let Some(e) = e {
            jac(g, 2, r, *e);
        }
    }
    let dqdt: Vec<Expr> = sys.forces.iter().map(|&f| g.diff(f, 0)).collect();
    let exprs: Vec<Expr> = entries.iter().map(|e| e.3).collect();
    let tape = g.compile(&exprs);
    let dqdt_tape = g.compile(&dqdt);
    let mut vars = vec![t];
    vars.extend_from_slice(&x);
    vars.extend_from_slice(&acc);
    vars.extend_from_slice(&lambda);
    let values = eval_tape(&tape, &vars);
    let ne = e_rows.len();
    let ny = outputs.len();
    let mut ez = DMatrix::zeros(ne, nz);
    let mut fz = DMatrix::zeros(nq, nz);
    let mut yz = DMatrix::zeros(ny, nz);
    for (&(block, r, k, _), &v) in entries.iter().zip(&values) {
        if !v.is_finite() {
            return Err(LinearizeError::NonFinite(match block {
                0 => format!("a derivative of the equations (row {r})"),
                1 => format!("a derivative of the kinematics of {}", sys0.coords[r].name),
                _ => format!("a derivative of output {}", outputs[r].0),
            })
            .into());
        }
        match block {
            0 => ez[(r, k)] = v,
            1 => fz[(r, k)] = v,
            _ => yz[(r, k)] = v,
        }
    }

    // ∂E3/∂u = −∂Q/∂u (E3 = M v' − Q + G_vᵀλ)
    let base_dqdt = eval_tape(&dqdt_tape, &vars);
    let dq_du = input_forces(scene, (nq, nv), &vars[..1 + nq + nv], &base_dqdt)?;
    let ni = scene.inputs.len();
    let mut eu = DMatrix::zeros(ne, ni);
    for k in 0..ni {
        for j in 0..nv {
            eu[(2 * nc + j, k)] = -dq_du[(j, k)];
        }
    }

    // in the chart: E_z̃ = E_z ∂z/∂z̃, y_z̃ likewise, the coordinates' rates by z̃
    let (ez, mut yz, fz, nq, nz) = match &chart {
        Some(ch) => {
            let nzt = ch.p.ncols();
            (&ez * &ch.p, &yz * &ch.p, ch.rates(&fz), ch.nq(), nzt)
        }
        None => (ez, yz, fz, nq, nz),
    };

    // z's split: x = [q_I, v_I], w = [q_D, v_D, v', λ]
    let x_z: Vec<usize> = part
        .ind_q
        .iter()
        .copied()
        .chain(part.ind_v.iter().map(|&j| nq + j))
        .collect();
    let w_z: Vec<usize> = part
        .dep_q
        .iter()
        .copied()
        .chain(part.dep_v.iter().map(|&j| nq + j))
        .chain((0..nv + nc).map(|k| nq + nv + k))
        .collect();
    let nx = x_z.len();
    if w_z.len() != ne {
        return Err(singular(format!(
            "{} dependent unknowns for {} equations",
            w_z.len(),
            ne
        )));
    }
    let ew = DMatrix::from_fn(ne, ne, |r, k| ez[(r, w_z[k])]);
    let ex = DMatrix::from_fn(ne, nx, |r, k| ez[(r, x_z[k])]);
    let svd = ew.clone().svd(false, false);
    let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
    if smin.is_nan() || smin <= 1e-13 * smax {
        return Err(singular(format!(
            "the dependent unknowns are not fixed by the states (condition {:.1e}): a degree of freedom without inertia or a singular configuration",
            smax / smin
        )));
    }
    let lu = ew.lu();
    let solve = |rhs: &DMatrix<f64>| {
        lu.solve(rhs)
            .map(|x| -x)
            .ok_or_else(|| singular("the dependent unknowns' Jacobian has a zero pivot".into()))
    };
    let dwdx = solve(&ex)?;
    let dwdu = solve(&eu)?;
    let mut zx = DMatrix::zeros(nz, nx);
    let mut zu = DMatrix::zeros(nz, ni);
    for (k, &z) in x_z.iter().enumerate() {
        zx[(z, k)] = 1.0;
    }
    for (r, &z) in w_z.iter().enumerate() {
        for k in 0..nx {
            zx[(z, k)] = dwdx[(r, k)];
        }
        for k in 0..ni {
            zu[(z, k)] = dwdu[(r, k)];
        }
    }
    // f = [(K v)_I, v'_I]
    let mut f = DMatrix::zeros(nx, nz);
    for (r, &i) in part.ind_q.iter().enumerate() {
        f.set_row(r, &fz.row(i));
    }
    for (r, &j) in part.ind_v.iter().enumerate() {
        f[(part.ind_q.len() + r, nq + nv + j)] = 1.0;
    }
    let a = &f * &zx;
    let b = &f * &zu;
    // outputs: a state (a unit row), or a column's expression
    for (r, (_, e, state)) in outputs.iter().enumerate() {
        if e.is_none() {
            yz[(r, x_z[*state])] = 1.0;
        }
    }
    let cm = &yz * &zx;
    let dm = &yz * &zu;

    // an equilibrium: at rest and not accelerating; elsewhere A's eigenvalues are not modes
    let fastest = x[sys0.nq()..]
        .iter()
        .chain(&acc)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let equilibrium = matches!(options.at, OperatingPoint::Equilibrium) || fastest <= AT_REST;
    let mut notes = notes;
    let eigenvalues = eigenvalues_of(&a);
    if eigenvalues
        .iter()
        .any(|e| !(e.0.is_finite() && e.1.is_finite()))
    {
        return Err(LinearizeError::NonFinite(
            "the eigenvalues of A (the QR iteration does not converge)".into(),
        )
        .into());
    }
    let modes = if equilibrium {
        modes_of(&a, &states, part.ind_q.len())
    } else {
        notes.push(format!(
            "the operating point at t = {t} moves (largest velocity or acceleration {fastest:.3e}): it is not an equilibrium, so A's eigenvalues (eigenvalues) tell how deviations grow or turn at that instant, not modes of vibration (no frequencies, no damping ratios)"
        ));
        Vec::new()
    };
    Ok(LinearModel {
        at: options.at.to_string(),
        t,
        // the run CSV's names: a spatial body's unit quaternion as qw…qz (§23)
        operating_point: crate::analysis::equilibrium::run_coordinates(sys0, &x[..sys0.nq()])
            .into_iter()
            .chain(
                sys0.velocities
                    .iter()
                    .zip(&x[sys0.nq()..])
                    .map(|(c, &v)| (c.name.clone(), v)),
            )
            .collect(),
        states,
        inputs: scene.inputs.iter().map(|u| u.name.clone()).collect(),
        outputs: outputs.into_iter().map(|o| o.0).collect(),
        a,
        b,
        c: cm,
        d: dm,
        equilibrium,
        eigenvalues,
        modes,
        notes,
        cpu_seconds: 0.0,
    })
}

/// The operating point `(t, [q, v])`: the static equilibrium at `t_start`, at rest, or the
/// scene's solved state at `T` projected onto the joints (the least change).
fn operating_point(
    model: &Model,
    sys: &MultibodySystem,
    tapes: &crate::dae::MechanicsTapes,
    at: OperatingPoint,
    t_start: f64,
) -> Result<(f64, Vec<f64>)> {
    let nv = sys.nv();
    let (t, x) = match at {
        OperatingPoint::Equilibrium => {
            let eq = model.equilibrium()?;
            let mut x: Vec<f64> = eq.coordinates.iter().map(|(_, v)| *v).collect();
            x.extend(std::iter::repeat_n(0.0, nv));
            (t_start, x)
        }
        OperatingPoint::Time(tt) => {
            if tt < t_start {
                return Err(LinearizeError::BeforeStart { t: tt, t_start }.into());
            }
            let t_end = model
                .default_options()
                .output_times
                .last()
                .copied()
                .unwrap_or(t_start);
            if tt > t_end {
                return Err(LinearizeError::AfterEnd { t: tt, t_end }.into());
            }
            let x0 = if tt == t_start {
                sys.initial_state()
            } else {
                solved_state(model, sys, tt)?
            };
            let init = crate::dae::consistent_state_from(sys, tapes, tt, &x0)?;
            let mut x = init.q;
            x.extend(init.v);
            (tt, x)
        }
    };
    if let Some(k) = x.iter().position(|v| !v.is_finite()) {
        let name = sys
            .coords
            .iter()
            .chain(&sys.velocities)
            .nth(k)
            .map_or(String::new(), |c| c.name.clone());
        return Err(LinearizeError::NonFinite(name).into());
    }
    Ok((t, x))
}

/// Refuses `given` independent `what` where the joints leave `left`.
fn count_given(given: usize, left: usize, what: &str) -> Result<()> {
    if given != left {
        return Err(LinearizeError::States(format!(
            "{given} independent {what} given, the joints leave {left}"
        ))
        .into());
    }
    Ok(())
}

/// The indices of the named independent coordinates and velocities (each list sorted, without
/// repeats), refused naming the first name that is neither; `what` follows "is not a coordinate
/// or velocity" in that refusal and opens the parenthesis that lists the known names (it ends
/// in "they are ").
fn given_states(
    names: &[String],
    q_names: &[impl AsRef<str>],
    v_names: &[impl AsRef<str>],
    what: &str,
) -> Result<(Vec<usize>, Vec<usize>)> {
    let (mut ind_q, mut ind_v) = (Vec::new(), Vec::new());
    for n in names {
        if let Some(i) = q_names.iter().position(|c| c.as_ref() == n) {
            ind_q.push(i);
        } else if let Some(j) = v_names.iter().position(|c| c.as_ref() == n) {
            ind_v.push(j);
        } else {
            let known: Vec<&str> = q_names
                .iter()
                .map(AsRef::as_ref)
                .chain(v_names.iter().map(AsRef::as_ref))
                .collect();
            return Err(LinearizeError::States(format!(
                "'{n}' is not a coordinate or velocity{what}{})",
                known.join(", ")
            ))
            .into());
        }
    }
    for ind in [&mut ind_q, &mut ind_v] {
        ind.sort_unstable();
        ind.dedup();
    }
    Ok((ind_q, ind_v))
}

/// The partition at the operating point `(t, x)`: the causality's there (with a note when it
/// is not the start's), or the one whose independent coordinates are named; refused where the
/// joints' Jacobian loses rank or its dependent block is nearly singular.
fn choose_partition(
    sys0: &MultibodySystem,
    states: Option<&[String]>,
    t_start: f64,
    t: f64,
    x: &[f64],
) -> Result<(crate::partition::Partition, Vec<String>)> {
    let nq = sys0.nq();
    let singular = |why: String| Error::from(LinearizeError::Singular { t, why });
    let mut sp = sys0.clone();
    let cp = ConstraintExprs::derive(&mut sp);
    let psys = PartitionedSystem::new(&mut sp, &cp);
    let causal = crate::partition::causal::CausalPartition::new(sys0, t_start);
    let mut notes = Vec::new();
    let part = match states {
        Some(names) => named_partition(sys0, &psys, t, x, names)?,
        None => {
            let preferred = causal.preferred_at(t, &x[..nq]);
            let p = psys.choose(t, x, &preferred).ok_or_else(|| {
                let redundant = causal.redundant_rows(&sys0.rows);
                if redundant.is_empty() {
                    singular(format!(
                        "the joints' Jacobian loses rank (joints {}): a singular configuration",
                        joint_list(sys0)
                    ))
                } else {
                    let rows: Vec<String> = redundant
                        .iter()
                        .map(|&i| format!("{}.{}", sys0.rows[i].joint, sys0.rows[i].direction))
                        .collect();
                    singular(format!(
                        "the joints' Jacobian loses rank (rows {} depend on the others): a singular configuration, or redundant joints",
                        rows.join(", ")
                    ))
                }
            })?;
            if let Some(start) = causal.dependent() {
                if start != p.dep_v {
                    let names = |d: &[usize]| {
                        d.iter()
                            .map(|&j| sys0.velocities[j].name.clone())
                            .collect::<Vec<_>>()
                            .join(", ")
                    };
                    notes.push(format!(
                        "the partition is re-chosen at the operating point: dependent velocities [{}] (at the start [{}])",
                        names(&p.dep_v),
                        names(&start)
                    ));
                }
            }
            p
        }
    };
    let condition = psys.condition(&part, t, x);
    if !PartitionPolicy::linearizable(condition) {
        return Err(singular(format!(
            "the dependent block of the joints' Jacobian has condition {condition:.1e} (joints {}): a singular configuration",
            joint_list(sys0)
        )));
    }

    Ok((part, notes))
}

/// The partition in the spatial bodies' chart ([`chart::Chart`]) at the operating point
/// `(t, x)`: the translations dependent where the joints allow (the seed's causality), the
/// attitude angles and the other coordinates independent; or the named independent chart
/// coordinates and velocities. Refused where the joints' Jacobian loses rank or its dependent
/// block is nearly singular.
fn chart_partition(
    sys0: &MultibodySystem,
    ch: &chart::Chart,
    states: Option<&[String]>,
    t: f64,
    x: &[f64],
) -> Result<crate::partition::Partition> {
    let singular = |why: String| Error::from(LinearizeError::Singular { t, why });
    let mut sp = sys0.clone();
    let cp = ConstraintExprs::derive(&mut sp);
    let psys = PartitionedSystem::new(&mut sp, &cp);
    let (gq, gv) = psys.jacobians(t, x);
    let (gq, gv) = ch.jacobians(&gq, &gv);
    let (nq, nv) = (gq.ncols(), gv.ncols());
    let rest = |n: usize, i: &[usize]| (0..n).filter(|k| !i.contains(k)).collect::<Vec<_>>();
    let (dep_q, dep_v) = match states {
        Some(names) => {
            let (ind_q, ind_v) = given_states(
                names,
                &ch.q_names,
                &ch.v_names,
                " of the chart (a spatial body's attitude is its rotation vector B.rx, B.ry, B.rz and its space-frame angular velocity B.wX, B.wY, B.wZ; they are ",
            )?;
            count_given(ind_q.len(), nq.saturating_sub(gq.nrows()), "coordinates")?;
            let dep_v = if ind_v.is_empty() {
                let preferred: Vec<bool> = (0..nv).map(|j| !ch.is_angular(j)).collect();
                select_dependent(&gv, &preferred).ok_or_else(|| {
                    LinearizeError::States("the joints' velocity Jacobian loses rank".into())
                })?
            } else {
                count_given(ind_v.len(), nv.saturating_sub(gv.nrows()), "velocities")?;
                rest(nv, &ind_v)
            };
            (rest(nq, &ind_q), dep_v)
        }
        None => {
            let lost = || {
                singular(format!(
                    "the joints' Jacobian loses rank (joints {}): a singular configuration, or redundant joints",
                    joint_list(sys0)
                ))
            };
            let preferred_q: Vec<bool> = (0..nq).map(|a| !ch.is_angle(a)).collect();
            let preferred_v: Vec<bool> = (0..nv).map(|j| !ch.is_angular(j)).collect();
            let dep_q = select_dependent(&gq, &preferred_q).ok_or_else(lost)?;
            let dep_v = select_dependent(&gv, &preferred_v).ok_or_else(lost)?;
            (dep_q, dep_v)
        }
    };
    let mut dep_q = dep_q;
    let mut dep_v = dep_v;
    dep_q.sort_unstable();
    dep_v.sort_unstable();
    let part = crate::partition::Partition {
        ind_q: rest(nq, &dep_q),
        ind_v: rest(nv, &dep_v),
        dep_q,
        dep_v,
    };
    let cond = dependent_condition(&gq, &part.dep_q).max(dependent_condition(&gv, &part.dep_v));
    if !PartitionPolicy::linearizable(cond) {
        return Err(singular(format!(
            "the dependent block of the joints' Jacobian has condition {cond:.1e} (joints {}): a singular configuration",
            joint_list(sys0)
        )));
    }
    Ok(part)
}

/// The accelerations and multipliers at `(t, x)`: `[M G_vᵀ; G_v 0][v'; λ] = [Q; −γ]`.
fn accelerations_and_multipliers(
    sys: &MultibodySystem,
    tapes: &crate::dae::MechanicsTapes,
    t: f64,
    x: &[f64],
) -> Result<(Vec<f64>, Vec<f64>)> {
    let (nv, nc) = (sys.nv(), sys.nc());
    let q_vals = MechTapeEval::new(tapes, t, x);
    let n = nv + nc;
    let mut k = DMatrix::zeros(n, n);
    for j in 0..nv {
        k[(j, j)] = sys.mass[j];
    }
    for i in 0..nc {
        for j in 0..nv {
            let gv = q_vals.gv[(i, j)];
            k[(nv + i, j)] = gv;
            k[(j, nv + i)] = gv;
        }
    }
    let mut rhs = DVector::zeros(n);
    for j in 0..nv {
        rhs[j] = q_vals.forces[j];
    }
    for i in 0..nc {
        rhs[nv + i] = -q_vals.gamma[i];
    }
    let why = "the saddle matrix [M G_vᵀ; G_v 0] is singular (a degree of freedom without inertia)";
    let sol = k
        .lu()
        .solve(&rhs)
        .ok_or_else(|| LinearizeError::Singular { t, why: why.into() })?;
    Ok((
        sol.rows(0, nv).iter().copied().collect::<Vec<_>>(),
        sol.rows(nv, nc).iter().copied().collect::<Vec<_>>(),
    ))
}

/// `∂Q/∂u` (`nv × inputs`) at the state slots `vars = [t, q, v]`: for each input, the scene
/// built once more with the input replaced by `u⁰ + (t − t*)`, whose `∂Q/∂t` at `t*` is
/// `∂Q/∂t + ∂Q/∂u_k` (symbolic derivatives), less the scene's own `∂Q/∂t` (`base_dqdt`).
fn input_forces(
    scene: &Scene,
    (nq, nv): (usize, usize),
    vars: &[f64],
    base_dqdt: &[f64],
) -> Result<DMatrix<f64>> {
    let t = vars[0];
    let mut out = DMatrix::zeros(nv, scene.inputs.len());
    for (k, u) in scene.inputs.iter().enumerate() {
        let moving = format!("{} + (t - ({:e}))", number(u.start), t);
        let sk = scene.with_input_expressions(&[(u.name.clone(), moving)]);
        let mk = Model::new(&sk)?;
        let Some(sysk) = mk.mechanism() else {
            return Err(LinearizeError::RawGraph.into());
        };
        if sysk.nq() != nq || sysk.nv() != nv {
            return Err(Error::Options(format!(
                "inputs '{}': the scene with the input moving has other coordinates",
                u.name
            )));
        }
        let mut gk = sysk.graph.clone();
        let dk: Vec<Expr> = sysk.forces.iter().map(|&f| gk.diff(f, 0)).collect();
        let vk = eval_tape(&gk.compile(&dk), vars);
        for j in 0..nv {
            out[(j, k)] = vk[j] - base_dqdt[j];
        }
    }
    Ok(out)
}

/// A number as the expression parser reads it (negative ones in parentheses).
fn number(x: f64) -> String {
    if x < 0.0 {
        format!("({x:e})")
    } else {
        format!("{x:e}")
    }
}

/// `G_v`, `Q`, `γ` at `(t, x)`.
struct MechTapeEval {
    gv: DMatrix<f64>,
    forces: Vec<f64>,
    gamma: Vec<f64>,
}

impl MechTapeEval {
    fn new(tapes: &crate::dae::MechanicsTapes, t: f64, x: &[f64]) -> Self {
        MechTapeEval {
            gv: tapes.gv.matrix(t, x),
            forces: crate::dae::MechanicsTapes::eval(&tapes.forces, t, x),
            gamma: crate::dae::MechanicsTapes::eval(&tapes.gamma, t, x),
        }
    }
}

fn eval_tape(tape: &Tape, vars: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; tape.n_outputs()];
    tape.eval(vars, &mut tape.workspace(), &mut out);
    out
}

/// The joints' names, for messages.
fn joint_list(sys: &MultibodySystem) -> String {
    let mut j: Vec<&str> = sys.rows.iter().map(|r| r.joint.as_str()).collect();
    j.dedup();
    j.join(", ")
}

/// The outputs asked for: `(name, expression or None for a state, state index)`. A column of
/// the bodies' motion is its expression of `[t, q, v]`; a driver's effort column is `−λ_row`
/// and its power `−λ_row ṡ(t)` ([`crate::mech::DriverOutput`]), with the multiplier of row
/// `i` in slot `lambda0 + i` of `graph` (the system's graph, extended).
fn resolve_outputs(
    sys: &MultibodySystem,
    graph: &mut crate::expr::ExprGraph,
    states: &[String],
    asked: &[String],
    lambda0: u32,
) -> Result<Vec<(String, Option<Expr>, usize)>> {
    if asked.is_empty() {
        return Ok(states
            .iter()
            .enumerate()
            .map(|(k, s)| (s.clone(), None, k))
            .collect());
    }
    let mut out = Vec::with_capacity(asked.len());
    for name in asked {
        if let Some(k) = states.iter().position(|s| s == name) {
            out.push((name.clone(), None, k));
            continue;
        }
        if let Some(o) = sys.outputs.iter().find(|o| o.name == *name) {
            out.push((name.clone(), Some(o.expr), 0));
            continue;
        }
        if let Some(d) = sys.drivers.iter().find(|d| d.columns().contains(name)) {
            let l = graph.var(lambda0 + d.row as u32);
            let effort = graph.neg(l);
            let e = if *name == d.columns()[0] {
                effort
            } else {
                graph.mul(effort, d.rate)
            };
            out.push((name.clone(), Some(e), 0));
            continue;
        }
        let why = if sys.reaction_columns().contains(name) {
            "a joint's reaction column is not linearized yet (its wrench solves the carrier body's virtual-power balance); give a column of the bodies' motion or a driver's effort".to_string()
        } else if name == "constraint_error" {
            "constraint_error is zero on the joints; it has no linearization".to_string()
        } else {
            let cols: Vec<&str> = sys.outputs.iter().map(|o| o.name.as_str()).collect();
            let drivers: Vec<String> = sys.drivers.iter().flat_map(|d| d.columns()).collect();
            let note = crate::scene::did_you_mean_note(
                name,
                states
                    .iter()
                    .map(String::as_str)
                    .chain(cols.iter().copied())
                    .chain(drivers.iter().map(String::as_str)),
            );
            format!(
                "not a column of the scene's run CSV{note} (columns: {})",
                cols.join(", ")
            )
        };
        return Err(LinearizeError::UnknownOutput {
            name: name.clone(),
            why,
        }
        .into());
    }
    Ok(out)
}

/// The partition whose independent coordinates (and velocities) are named.
fn named_partition(
    sys: &MultibodySystem,
    psys: &PartitionedSystem,
    t: f64,
    x: &[f64],
    names: &[String],
) -> Result<crate::partition::Partition> {
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let q_names: Vec<&str> = sys.coords.iter().map(|c| c.name.as_str()).collect();
    let v_names: Vec<&str> = sys.velocities.iter().map(|c| c.name.as_str()).collect();
    let (ind_q, mut ind_v) = given_states(names, &q_names, &v_names, " (they are ")?;
    count_given(ind_q.len(), nq - nc, "coordinates")?;
    let (gq, gv) = psys.jacobians(t, x);
    // q' = v: each coordinate's rate is its own velocity
    let mut g = sys.graph.clone();
    let identity = nq == nv && (0..nq).all(|i| sys.kinematics[i] == g.var(sys.v_slot(i)));
    if ind_v.is_empty() {
        if identity {
            ind_v = ind_q.clone();
        } else {
            let dep = select_dependent(&gv, &vec![false; nv]).ok_or_else(|| {
                LinearizeError::States("the joints' velocity Jacobian loses rank".into())
            })?;
            ind_v = (0..nv).filter(|j| !dep.contains(j)).collect();
        }
    }
    count_given(ind_v.len(), nv - nc, "velocities")?;
    let rest = |n: usize, i: &[usize]| (0..n).filter(|k| !i.contains(k)).collect::<Vec<_>>();
    let p = crate::partition::Partition {
        dep_q: rest(nq, &ind_q),
        dep_v: rest(nv, &ind_v),
        ind_q,
        ind_v,
    };
    let cond = dependent_condition(&gq, &p.dep_q).max(dependent_condition(&gv, &p.dep_v));
    if !PartitionPolicy::linearizable(cond) {
        return Err(LinearizeError::States(format!(
            "the joints do not fix the other coordinates from these (dependent block condition {cond:.1e})"
        ))
        .into());
    }
    Ok(p)
}

/// The state `[q, v]` the scene's solve reaches at `t`.
fn solved_state(model: &Model, sys: &MultibodySystem, t: f64) -> Result<Vec<f64>> {
    let mut opts = model.default_options();
    opts.output_times = vec![model.scene().solve.t_start, t];
    let sol = model.solve(&opts)?;
    let row = sol.rows.last().expect("two output times");
    let col = |name: &str| sol.columns.iter().position(|c| c == name).map(|k| row[k]);
    let mut x = Vec::with_capacity(sys.nq() + sys.nv());
    for c in &sys.coords {
        x.push(col(&c.name).ok_or_else(|| {
            Error::Options(format!("linearize: the run has no column {}", c.name))
        })?);
    }
    // the velocities from the bodies' velocity columns (linear in v): least squares
    let (nq, nv) = (sys.nq(), sys.nv());
    let linear: Vec<&crate::mech::OutputColumn> = sys
        .outputs
        .iter()
        .filter(|o| {
            matches!(
                o.name.rsplit('.').next(),
                Some("vx" | "vy" | "vz" | "omega")
            ) && col(&o.name).is_some()
        })
        .collect();
    let mut g = sys.graph.clone();
    let mut jv = Vec::new();
    for o in &linear {
        for j in 0..nv {
            jv.push(g.diff(o.expr, sys.v_slot(j)));
        }
    }
    let values: Vec<Expr> = linear.iter().map(|o| o.expr).collect();
    let mut vars = vec![t];
    vars.extend_from_slice(&x);
    vars.extend(std::iter::repeat_n(0.0, nv));
    let jm = DMatrix::from_row_slice(linear.len(), nv, &eval_tape(&g.compile(&jv), &vars));
    let y0 = eval_tape(&g.compile(&values), &vars);
    let rhs = DVector::from_iterator(
        linear.len(),
        linear
            .iter()
            .zip(&y0)
            .map(|(o, y)| col(&o.name).unwrap_or(0.0) - y),
    );
    let v = jm
        .svd(true, true)
        .solve(&rhs, 1e-12)
        .map_err(|e| Error::Options(format!("linearize: velocities at t = {t}: {e}")))?;
    debug_assert_eq!(x.len(), nq);
    x.extend(v.iter().copied());
    Ok(x)
}
