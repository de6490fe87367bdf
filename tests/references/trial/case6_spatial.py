"""Case 6b: spatial double pendulum on spherical joints (two axisymmetric bars, no spin about
their axes), and the same with point masses on massless distance links.
Reference: bar directions n1, n2 (unit vectors) with Lagrange multipliers (index 1, constant mass
matrix), DOP853 at rtol = atol = 1e-12; conservation of energy and of L_z checked."""
import math, sys
import numpy as np
from scipy.integrate import solve_ivp
from ref import *

g = np.array([0.0, 0.0, -9.81])

def reference(m1, m2, L1, L2, J1, J2, n1, n2, n1d, n2d, times, p1=0.5, p2=0.5):
    """c1 = p1 L1 n1, c2 = L1 n1 + p2 L2 n2 (centres at fractions p of the bars)."""
    I3 = np.eye(3); Z = np.zeros((3, 3))
    A1 = np.hstack([p1 * L1 * I3, Z]); A2 = np.hstack([L1 * I3, p2 * L2 * I3])
    M = m1 * A1.T @ A1 + m2 * A2.T @ A2 + np.block([[J1 * I3, Z], [Z, J2 * I3]])
    F = m1 * A1.T @ g + m2 * A2.T @ g
    def rhs(t, y):
        z, zd = y[:6], y[6:]
        Phi = np.zeros((2, 6)); Phi[0, :3] = z[:3]; Phi[1, 3:] = z[3:]
        gam = -np.array([zd[:3] @ zd[:3], zd[3:] @ zd[3:]])
        K = np.block([[M, Phi.T], [Phi, np.zeros((2, 2))]])
        sol = np.linalg.solve(K, np.concatenate([F, gam]))
        return np.concatenate([zd, sol[:6]])
    y0 = np.concatenate([n1, n2, n1d, n2d])
    s = solve_ivp(rhs, (times[0], times[-1]), y0, method="DOP853", t_eval=times, rtol=1e-12, atol=1e-12)
    assert s.success
    Y = s.y.T
    c1 = Y[:, :6] @ A1.T; c2 = Y[:, :6] @ A2.T
    E = np.array([0.5 * y[6:] @ M @ y[6:] - F @ y[:6] for y in Y])
    # L_z about the origin: sum m c x cdot + J n x nd (z comp)
    c1d = Y[:, 6:] @ A1.T; c2d = Y[:, 6:] @ A2.T
    Lz = (m1 * np.cross(c1, c1d) + m2 * np.cross(c2, c2d) + J1 * np.cross(Y[:, :3], Y[:, 6:9]) + J2 * np.cross(Y[:, 3:6], Y[:, 9:]))[:, 2]
    print(f"   reference: |n|-1 max {np.max(np.abs(np.linalg.norm(Y[:, :3], axis=1) - 1)):.1e}, energy drift {np.ptp(E):.1e}, Lz drift {np.ptp(Lz):.1e}")
    tip = c2 + (1 - p2) * L2 * Y[:, 3:6]
    return c1, c2, tip

T_END = 3.0
times = np.linspace(0, T_END, 301)
m1, m2, L1, L2 = 1.0, 0.8, 1.0, 0.7
Ja = 0.01
J1, J2 = m1 * L1**2 / 12, m2 * L2**2 / 12
n1 = np.array([1.0, 0, 0]); n2 = np.array([0, 1.0, 0])
n1d = np.array([0, 1.0, 0]); n2d = np.array([0.5, 0, 0.8])

def bars_scene(order=None, jorder=None):
    w1 = np.cross(n1, n1d); w2 = np.cross(n2, n2d)
    R2 = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    w2b = R2.T @ w2
    c1d = 0.5 * L1 * n1d; c2d = L1 * n1d + 0.5 * L2 * n2d
    bs = [{"name": "bar1", "mass": m1, "inertia": [Ja, J1, J1], "points": {"O": [-L1 / 2, 0, 0], "A": [L1 / 2, 0, 0]},
           "position": list(0.5 * L1 * n1), "cardan": [0, 0, 0], "velocity": list(c1d), "angular_velocity": list(w1)},
          {"name": "bar2", "mass": m2, "inertia": [Ja, J2, J2], "points": {"O": [-L2 / 2, 0, 0], "A": [L2 / 2, 0, 0]},
           "position": list(L1 * n1 + 0.5 * L2 * n2), "cardan": [math.pi / 2, 0, 0], "velocity": list(c2d),
           "angular_velocity": list(w2b)}]
    js = [{"name": "shoulder", "type": "spherical", "bodies": ["ground", "bar1"], "points": [[0, 0, 0], "O"]},
          {"name": "elbow", "type": "spherical", "bodies": ["bar1", "bar2"], "points": ["A", "O"]}]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "spherical_double_pendulum", "dimension": 3, "gravity": list(g), "bodies": bs, "joints": js,
            "outputs": ["bar2.A", "energy"],
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

def points_scene(link="distance"):
    c1d = L1 * n1d; c2d = L1 * n1d + L2 * n2d
    bs = [{"name": "p1", "mass": m1, "inertia": [0, 0, 0], "position": list(L1 * n1), "velocity": list(c1d)},
          {"name": "p2", "mass": m2, "inertia": [0, 0, 0], "position": list(L1 * n1 + L2 * n2), "velocity": list(c2d)}]
    js = [{"name": "l1", "type": "distance", "bodies": ["ground", "p1"], "points": [[0, 0, 0], [0, 0, 0]]},
          {"name": "l2", "type": "distance", "bodies": ["p1", "p2"], "points": [[0, 0, 0], [0, 0, 0]]}]
    return {"name": "point_double_pendulum_3d", "dimension": 3, "gravity": list(g), "bodies": bs, "joints": js,
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

def cmp3(res, refs):
    d = res["data"]; h = res["header"]
    if d is None: return float("nan")
    e = 0.0
    for col, arr in refs.items():
        for k, ax in enumerate("xyz"):
            e = max(e, np.max(np.abs(d[:, h.index(f"{col}.{ax}")] - arr[:len(d), k])))
    return e

def run3(tag, sc, refs, forms=(None, "ggl", "partitioned")):
    for f in forms:
        res = run(sc, tag, f); s = res["summary"] or {}
        print(f"{tag+'['+(f or 'default')+']':40s} rc={res['rc']} form={s.get('formulation')} steps={s.get('steps')} "
              f"t={s.get('t_reached')} pos_err={cmp3(res, refs):.2e} drift={s.get('energy_drift')} cerr={s.get('max_constraint_error')}")
        for w in s.get("warnings", []): print("     warning:", w[:250])
        if res["rc"]: print("     stderr:", res["stderr"][:500])

if __name__ == "__main__":
    c1, c2, tip = reference(m1, m2, L1, L2, J1, J2, n1, n2, n1d, n2d, times)
    run3("sph_double_pendulum", bars_scene(), {"bar1": c1, "bar2": c2, "bar2.A": tip})
    run3("sph_double_pendulum_reversed", bars_scene([1, 0], [1, 0]), {"bar1": c1, "bar2": c2, "bar2.A": tip}, forms=(None,))
    c1p, c2p, _ = reference(m1, m2, L1, L2, 0.0, 0.0, n1, n2, n1d, n2d, times, p1=1.0, p2=1.0)
    run3("point_double_pendulum_3d", points_scene(), {"p1": c1p, "p2": c2p})
