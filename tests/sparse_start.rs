//! The consistent start of large mechanisms by sparse Cholesky factorisations
//! (`dae::init`, from `SPARSE_START_UNKNOWNS` velocities and rows on) against the dense
//! pseudo-inverses (nalgebra's SVD, computed here independently), and its fallback to the SVD
//! when joints are redundant.

use bondmech::dae::{consistent_state_from, ConstraintExprs, MechanicsTapes};
use bondmech::report::generate::n_link_pendulum_json;
use bondmech::thresholds::SPARSE_START_UNKNOWNS;
use bondmech::{Model, Scene};
use nalgebra::{DMatrix, DVector};

fn model(json: &str) -> Model {
    Model::new(&Scene::from_json_str(json).unwrap()).unwrap()
}

fn inf(v: &DVector<f64>) -> f64 {
    v.amax()
}

#[test]
fn sparse_start_of_a_60_link_pendulum_is_the_least_change_projection_and_solves_the_saddle_system()
{
    let m = model(&n_link_pendulum_json(60, 0.1, 0.01));
    let mut sys = m.system().clone();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let (nq, nv, nc) = tapes.dims;
    assert!(
        nv + nc >= SPARSE_START_UNKNOWNS,
        "{nv} + {nc}: the sparse path is taken"
    );
    // velocities that violate the joints: v0_j = sin(j)
    let mut x0 = sys.initial_state();
    for j in 0..nv {
        x0[nq + j] = (j as f64).sin();
    }
    let st = consistent_state_from(&sys, &tapes, 0.0, &x0).unwrap();
    assert!(st.redundant_joints.is_empty());
    assert_eq!(st.rank, nc);
    let mut x = st.q.clone();
    x.extend(&st.v);
    let gv = tapes.gv.matrix(0.0, &x);
    let v = DVector::from_column_slice(&st.v);
    let v0 = DVector::from_column_slice(&x0[nq..]);
    // the joints hold: G_v v = 0 (to rounding of |G_v| |v|, entries and velocities O(1))
    assert!(inf(&(&gv * &v)) < 1e-12, "{}", inf(&(&gv * &v)));
    // the least change: v0 − v = G_v⁺ G_v v0, the pseudo-inverse by nalgebra's SVD
    let svd = gv.clone().svd(true, true);
    let dv_ref = svd.solve(&(&gv * &v0), 1e-12).unwrap();
    let dv = &v0 - &v;
    let err = inf(&(&dv - &dv_ref)) / inf(&dv_ref);
    assert!(
        err < 1e-10,
        "velocity projection differs from G_v⁺ G_v v0 by {err:e}"
    );
    // accelerations and multipliers solve [M G_vᵀ; G_v 0] [v'; λ] = [Q; −γ]
    let q = DVector::from_vec(MechanicsTapes::eval(&tapes.forces, 0.0, &x));
    let gamma = DVector::from_vec(MechanicsTapes::eval(&tapes.gamma, 0.0, &x));
    let mass = DVector::from_column_slice(&sys.mass);
    let vdot = DVector::from_column_slice(&st.vdot);
    let lambda = DVector::from_column_slice(&st.lambda);
    let r1 = mass.component_mul(&vdot) + gv.transpose() * &lambda - &q;
    let r2 = &gv * &vdot + &gamma;
    let scale = inf(&q).max(inf(&(gv.transpose() * &lambda)));
    assert!(
        inf(&r1) < 1e-10 * scale,
        "M v' + G_vᵀ λ − Q = {:e}",
        inf(&r1)
    );
    assert!(
        inf(&r2) < 1e-10 * inf(&vdot).max(inf(&gamma)),
        "G_v v' + γ = {:e}",
        inf(&r2)
    );
    // and λ is the dense saddle-point solution (nalgebra's LU of the full system)
    let n = nv + nc;
    let mut a = DMatrix::zeros(n, n);
    for j in 0..nv {
        a[(j, j)] = sys.mass[j];
    }
    a.view_mut((nv, 0), (nc, nv)).copy_from(&gv);
    a.view_mut((0, nv), (nv, nc)).copy_from(&gv.transpose());
    let mut b = DVector::zeros(n);
    b.rows_mut(0, nv).copy_from(&q);
    b.rows_mut(nv, nc).copy_from(&(-&gamma));
    let sol = a.lu().solve(&b).unwrap();
    let lam_ref = sol.rows(nv, nc).into_owned();
    let err = inf(&(&lambda - &lam_ref)) / inf(&lam_ref);
    assert!(err < 1e-8, "λ differs from the dense solution by {err:e}");
}

#[test]
fn sparse_start_falls_back_to_the_svd_and_names_a_redundant_joint_of_a_large_mechanism() {
    // a 60-link pendulum with the ground pin written twice: its rows are linearly dependent
    let mut v: serde_json::Value =
        serde_json::from_str(&n_link_pendulum_json(60, 0.1, 0.01)).unwrap();
    let joints = v["joints"].as_array_mut().unwrap();
    let mut twin = joints[0].clone();
    twin["name"] = "pivot_again".into();
    joints.push(twin);
    let m = model(&v.to_string());
    let mut sys = m.system().clone();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let (_, nv, nc) = tapes.dims;
    assert!(nv + nc >= SPARSE_START_UNKNOWNS);
    let st = consistent_state_from(&sys, &tapes, 0.0, &sys.initial_state()).unwrap();
    assert_eq!(st.rank, nc - 2);
    assert!(
        st.redundant_joints.iter().any(|j| j == "pivot_again"),
        "{:?}",
        st.redundant_joints
    );
}
