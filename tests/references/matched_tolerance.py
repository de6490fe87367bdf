"""The matched-tolerance table of issue 46: the default (`dae`) against `ggl` at rtol 1e-7, 1e-8, 1e-9
(atol = rtol / 100) on mechanisms with independent references, nothing of bondmech in them:

* five_bar: four uniform bars (1 kg/m), ground pivots 0.4 m apart, cranks 0.3 m, couplers 0.7 m,
  released from rest, 1 s; reference: the four link angles with the loop closure kept by
  multipliers (`ref.PlanarConstrained`), DOP853 at 1e-12;
* slider_crank_fast: the trial's offset slider-crank (case 2) spinning at 14 rad/s, 1 s; a 1-DOF
  Lagrange model in the crank angle (`ref.Planar`);
* spherical, spherical100: a 1 kg point mass on a 1 m distance link in 3D thrown horizontally at
  2 m/s, 10 s and 100 s; the (θ, φ) Lagrange ODE at 1e-13;
* double_pendulum: scenes/double_pendulum.json, 3 s; Newton–Euler with multipliers (`ref.PinModel`);
* slider_crank: scenes/slider_crank.json (torque and gas force), 1 s; a 1-DOF Lagrange model;
* bead_pivot: scenes/bead_slot_through_pivot.json, 3 s; the polar Lagrange model;
* heavy_top: scenes/heavy_top.json, 5 s; Euler's equations about the fixed point with a rotation
  matrix (compared: the attitude matrix's entries and the centre over the length);
* a01: scenes/distance_pendulum.json over 100 s; the exact elliptic solution.

    python3 tests/references/matched_tolerance.py [MECH,MECH,...] [default,ggl,...]

with RTOLS=1e-9,1e-10,1e-11 to change the tolerances, BONDMECH=path/to/bondmech (default the
release build), REPEAT=k to take each CPU time as the least of k runs. Prints, per mechanism and tolerance, each formulation's largest coordinate error
(m, or attitude entry), steps and CPU, and the default's error and CPU over ggl's. CPU ratios from
one run only; the machine's load moves them.
"""
import json, math, os, subprocess, sys, time
import numpy as np
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "trial"))
from ref import FiveBar, Planar, PlanarConstrained, bar, PinModel
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.special import ellipj, ellipk

BIN = os.environ.get("BONDMECH", os.path.join(ROOT, "target/release/bondmech"))
OUT = os.environ.get("TRIAL_OUT", "/tmp/matched_tolerance"); os.makedirs(OUT, exist_ok=True)
CACHE = os.path.join(OUT, "references"); os.makedirs(CACHE, exist_ok=True)

def cached(name, fn):
    p = os.path.join(CACHE, name + ".npy")
    if os.path.exists(p):
        return np.load(p)
    a = fn(); np.save(p, a); return a

def planar_cols(names):
    return [f"{n}.{c}" for n in names for c in ("x", "y")]

# ---- five-bar: ground 0.4, cranks 0.3, couplers 0.7, uniform bars (1 kg/m), from rest, 1 s
def five_bar():
    lengths = [0.3, 0.7, 0.7, 0.3]
    five = FiveBar(0.4, lengths, lengths)
    model = five.model
    q0 = five.start(math.radians(120), math.radians(60))
    T = 1.0
    times = np.linspace(0, T, 101)
    def mk():
        Y = model.solve(np.array(q0 + [0, 0, 0, 0]), times)
        r = model.bodies_at(times, Y)
        return np.column_stack([r[n][:, k] for n in ["c1", "k2", "k3", "c4"] for k in (0, 1)])
    R = cached("five_bar", mk)
    Y0 = model.bodies_at(times[:1], np.array([q0 + [0] * 4]))
    sc = five.scene("five_bar", {n: Y0[n][0] for n in Y0}, {"t_end": T, "output_step": 0.01})
    return sc, planar_cols(["c1", "k2", "k3", "c4"]), R

# ---- fast offset slider-crank (case 2 with omega0 = 14), 1 s
def slider_crank_fast(W0=14.0, T=1.0):
    r, l, e = 0.15, 0.5, 0.08
    mc, mr, mp = 1.0, 0.6, 0.4
    Ic, Ir = mc * r**2 / 12, 0.02
    cA = (0.2, 0.04)
    phi = sp.symbols("phi")
    A = sp.Matrix([r * sp.cos(phi), r * sp.sin(phi)])
    xP = A[0] + sp.sqrt(l**2 - (e - A[1])**2)
    psi = sp.atan2(e - A[1], xP - A[0])
    G = A + sp.Matrix([[sp.cos(psi), -sp.sin(psi)], [sp.sin(psi), sp.cos(psi)]]) * sp.Matrix(cA)
    bodies = [("crank", mc, Ic, r / 2 * sp.cos(phi), r / 2 * sp.sin(phi), phi),
              ("rod", mr, Ir, G[0], G[1], psi),
              ("piston", mp, 0.0, xP, sp.Float(e), sp.Float(0.0))]
    model = Planar([phi], bodies)
    PHI0 = math.pi / 2
    times = np.linspace(0, T, int(round(T * 100)) + 1)
    def mk():
        Y = model.solve(np.array([PHI0, W0]), times)
        rr = model.bodies_at(times, Y)
        return np.column_stack([rr[n][:, k] for n in ["crank", "rod", "piston"] for k in (0, 1)])
    R = cached(f"slider_crank_fast_{W0}_{T}", mk)
    Y0 = np.array([PHI0, W0])
    x0 = model.bodies_at(times[:1], np.array([[PHI0, W0]]))
    v0 = model.velocities(Y0)
    bs = [{"name": "crank", "mass": mc, "inertia": Ic, "points": bar(r), "position": [float(x0["crank"][0][0]), float(x0["crank"][0][1])], "angle": PHI0},
          {"name": "rod", "mass": mr, "inertia": Ir, "points": {"A": [-cA[0], -cA[1]], "B": [l - cA[0], -cA[1]]},
           "position": [float(x0["rod"][0][0]), float(x0["rod"][0][1])], "angle": float(x0["rod"][0][2])},
          {"name": "piston", "mass": mp, "inertia": 0.0, "position": [float(x0["piston"][0][0]), e]}]
    for b in bs:
        vx, vy, w = v0[b["name"]]; b["velocity"] = [vx, vy]
        if b["inertia"] > 0: b["angular_velocity"] = w
    js = [{"name": "main", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0.0, 0.0], "O"]},
          {"name": "crankpin", "type": "revolute", "bodies": ["crank", "rod"], "points": ["A", "A"]},
          {"name": "wrist", "type": "revolute", "bodies": ["rod", "piston"], "points": ["B", [0.0, 0.0]]},
          {"name": "cylinder", "type": "prismatic", "bodies": ["ground", "piston"], "points": [[0.0, e], [0.0, 0.0]], "axis": [1.0, 0.0]}]
    sc = {"name": "offset_slider_crank", "dimension": 2, "gravity": [0.0, -9.81], "bodies": bs, "joints": js,
          "solve": {"t_end": T, "output_step": 0.01}}
    return sc, planar_cols(["crank", "rod", "piston"]), R

# ---- spherical pendulum 10 s
def spherical(T=10.0):
    g, L, v0 = 9.81, 1.0, 2.0
    times = np.linspace(0, T, int(round(T * 100)) + 1)
    def mk():
        def rhs(t, y):
            th, ph, thd, phd = y
            return [thd, phd, math.sin(th) * math.cos(th) * phd**2 - g * math.sin(th), -2 * math.cos(th) / math.sin(th) * thd * phd]
        s = solve_ivp(rhs, (0, T), [math.pi / 2, 0, 0, v0], method="DOP853", t_eval=times, rtol=1e-13, atol=1e-13)
        th, ph = s.y[0], s.y[1]
        return np.column_stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), -np.cos(th)])
    R = cached(f"spherical_{T}", mk)
    sc = {"name": "spherical_pendulum", "dimension": 3, "gravity": [0, 0, -g],
          "bodies": [{"name": "bob", "mass": 1.0, "inertia": [0, 0, 0], "position": [L, 0, 0], "velocity": [0, v0, 0]}],
          "joints": [{"name": "rod", "type": "distance", "bodies": ["ground", "bob"], "points": [[0, 0, 0], [0, 0, 0]]}],
          "solve": {"t_end": T, "output_step": 0.01}}
    return sc, ["bob.x", "bob.y", "bob.z"], R

# ---- double pendulum (bundled scene), reference by PinModel
def double_pendulum(T=3.0):
    sc = json.load(open(os.path.join(ROOT, "scenes", "double_pendulum.json")))
    sc["solve"] = {"t_end": T, "output_step": 0.01}
    times = np.linspace(0, T, int(round(T * 100)) + 1)
    def mk():
        pm = PinModel([(1.0, 1 / 12), (1.0, 1 / 12)], [(None, (0, 0), 0, (-0.5, 0)), (0, (0.5, 0), 1, (-0.5, 0))])
        Z = pm.solve(np.array([0.5, 0, 0, 1.5, 0, 0]), times)
        return Z[:, [0, 1, 3, 4]]
    R = cached(f"double_pendulum_{T}", mk)
    return sc, planar_cols(["bar1", "bar2"]), R

# ---- A01: point mass on massless 1 m link from horizontal, exact solution
def a01(T=100.0, step=0.01):
    sc = json.load(open(os.path.join(ROOT, "scenes", "distance_pendulum.json")))
    sc["solve"] = {"t_end": T, "output_step": step}
    g, L = 9.81, 1.0
    n = int(round(T / step)) + 1
    times = np.linspace(0, T, n)
    # released horizontal: amplitude pi/2; theta(t) = 2 asin(k sn(K - w t, k)), k = sin(pi/4)
    k = math.sin(math.pi / 4); w = math.sqrt(g / L); K = ellipk(k * k)
    sn, cn, dn, _ = ellipj(K - w * times, k * k)
    th = 2 * np.arcsin(k * sn)
    R = np.column_stack([L * np.sin(th), -L * np.cos(th)])
    return sc, None, R

MECH = {"five_bar": five_bar, "slider_crank_fast": slider_crank_fast, "spherical": spherical,
        "double_pendulum": double_pendulum, "a01": a01}

def run(name, sc, cols, R, rtol, formulation=None, extra=(), tag=""):
    sc = json.loads(json.dumps(sc))
    sc["solve"]["rtol"] = rtol; sc["solve"]["atol"] = rtol / 100
    if os.environ.get("ENERGY_INVARIANT"): sc["solve"]["energy_invariant"] = os.environ["ENERGY_INVARIANT"]
    path = os.path.join(OUT, f"{name}{tag}.json"); json.dump(sc, open(path, "w"))
    csv = os.path.join(OUT, f"{name}{tag}.{formulation or 'default'}.{rtol}.csv")
    summ = csv + ".summary.json"
    cmd = [BIN, "run", path, "--out", csv, "--summary", summ] + list(extra)
    if formulation: cmd += ["--formulation", formulation]
    cpu = float("inf")
    for _ in range(int(os.environ.get("REPEAT", "1"))):
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            return {"err": float("nan"), "rc": p.returncode, "stderr": p.stderr[-400:]}
        cpu = min(cpu, json.load(open(summ))["cpu_seconds"])
    s = json.load(open(summ))
    s["cpu_seconds"] = cpu
    import csv as C
    rows = list(C.reader(open(csv))); h = rows[0]; d = np.array([[float(x) for x in r] for r in rows[1:]])
    if cols is None:  # a01: bob
        cols = [c for c in h if c.endswith(".x") or c.endswith(".y")][:2]
    D = d[:, [h.index(c) for c in cols]]
    err = float(np.max(np.abs(D - R[: len(D)])))
    return {"err": err, "steps": s["steps"], "cpu": s["cpu_seconds"], "etf": s["error_test_failures"],
            "resel": s.get("index1_reselections"), "inv": s.get("energy_invariant"), "warn": len(s["warnings"]), "rc": 0}

def main():
    names = sys.argv[1].split(",") if len(sys.argv) > 1 else list(MECH)
    forms = sys.argv[2].split(",") if len(sys.argv) > 2 else ["default", "ggl"]
    rtols = [float(x) for x in os.environ.get("RTOLS", "1e-7,1e-8,1e-9").split(",")]
    for name in names:
        sc, cols, R = MECH[name]()
        res = {}
        for rt in rtols:
            for f in forms:
                res[(rt, f)] = run(name, sc, cols, R, rt, None if f == "default" else f)
        for rt in rtols:
            line = f"{name:18s} {rt:.1e}"
            for f in forms:
                r = res[(rt, f)]
                if r["rc"]:
                    line += f" | {f}: FAIL {r['stderr'][:100]}"
                else:
                    line += f" | {f}: err {r['err']:.2e} st {r['steps']} cpu {r['cpu']*1e3:.1f}ms etf {r['etf']} rs {r['resel']} inv {r['inv']}"
            if "default" in forms and "ggl" in forms and not res[(rt,'default')]['rc'] and not res[(rt,'ggl')]['rc']:
                line += f" || err×{res[(rt,'default')]['err']/res[(rt,'ggl')]['err']:.2f} cpu×{res[(rt,'default')]['cpu']/res[(rt,'ggl')]['cpu']:.2f}"
            print(line, flush=True)
        if "default" in forms:
            if (1e-7, "default") in res and (1e-9, "default") in res:
                print(f"{name:18s} default shrink 1e-7→1e-9: {res[(1e-7,'default')]['err']/res[(1e-9,'default')]['err']:.1f}×", flush=True)

def heavy_top(T=5.0):
    sc = json.load(open(os.path.join(ROOT, "scenes", "heavy_top.json")))
    sc["solve"] = {"t_end": T, "output_step": 0.01}
    times = np.linspace(0, T, int(round(T * 100)) + 1)
    m, l, g = 1.0, 0.5, 9.81
    J = np.diag([0.02 + m * l * l, 0.02 + m * l * l, 0.03])
    Ji = np.linalg.inv(J)
    def mk():
        def rhs(t, y):
            w = y[:3]; Rm = y[3:].reshape(3, 3)
            F = Rm.T @ np.array([0, 0, -m * g])
            tau = np.cross([0, 0, l], F)
            wd = Ji @ (np.cross(J @ w, w) + tau)
            W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
            return np.concatenate([wd, (Rm @ W).reshape(9)])
        a = math.radians(30)
        R0 = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
        s = solve_ivp(rhs, (0, T), np.concatenate([[0, 0, 40.0], R0.reshape(9)]), method="DOP853", t_eval=times, rtol=1e-13, atol=1e-13)
        Rs = s.y[3:].T.reshape(-1, 3, 3)
        # the columns compared: the rotation matrix's entries and the centre over l
        c = Rs[:, :, 2] * l
        return np.column_stack([Rs.reshape(-1, 9), c / l])
    return sc, "top", cached(f"heavy_top_{T}", mk)

MECH["heavy_top"] = heavy_top
_run = run
def run(name, sc, cols, R, rtol, formulation=None, extra=(), tag=""):
    if cols != "top":
        return _run(name, sc, cols, R, rtol, formulation, extra, tag)
    r = _run(name, sc, ["top.qw", "top.qx", "top.qy", "top.qz", "top.x", "top.y", "top.z"], np.zeros((len(R), 7)), rtol, formulation, extra, tag)
    if r["rc"]:
        return r
    import csv as C
    csv = os.path.join(OUT, f"{name}{tag}.{formulation or 'default'}.{rtol}.csv")
    rows = list(C.reader(open(csv))); h = rows[0]; d = np.array([[float(x) for x in q] for q in rows[1:]])
    q = d[:, [h.index(c) for c in ["top.qw", "top.qx", "top.qy", "top.qz"]]]
    w, x, y, z = q.T
    Rq = np.stack([1 - 2 * (y*y + z*z), 2 * (x*y - w*z), 2 * (x*z + w*y),
                   2 * (x*y + w*z), 1 - 2 * (x*x + z*z), 2 * (y*z - w*x),
                   2 * (x*z - w*y), 2 * (y*z + w*x), 1 - 2 * (x*x + y*y)], axis=1)
    cen = d[:, [h.index(c) for c in ["top.x", "top.y", "top.z"]]] / 0.5
    n = len(d)
    r["err"] = float(max(np.max(np.abs(Rq - R[:n, :9])), np.max(np.abs(cen - R[:n, 9:]))))
    return r


def slider_crank_bundled(T=1.0):
    sc = json.load(open(os.path.join(ROOT, "scenes", "slider_crank.json")))
    sc["solve"] = {"t_end": T, "output_step": 0.01}
    r, l = 0.1, 0.3
    phi = sp.symbols("phi")
    A = sp.Matrix([r * sp.cos(phi), r * sp.sin(phi)])
    yP = A[1] + sp.sqrt(l**2 - A[0]**2)
    psi = sp.atan2(yP - A[1], -A[0])
    G = (A + sp.Matrix([0, yP])) / 2
    bodies = [("crank", 1.0, 0.0008333333333333335, r / 2 * sp.cos(phi), r / 2 * sp.sin(phi), phi),
              ("rod", 0.5, 0.00375, G[0], G[1], psi),
              ("piston", 0.3, 0.0002, sp.Float(0), yP, sp.Float(0))]
    t = sp.Symbol("t")
    # generalised force: torque 1.5 on the crank, gas force -10 max(0, cos phi) along y on the piston
    force = [1.5 + sp.diff(yP, phi) * (-10) * sp.Max(0, sp.cos(phi))]
    model = Planar([phi], bodies, force=force)
    times = np.linspace(0, T, int(round(T * 100)) + 1)
    def mk():
        Y = model.solve(np.array([math.pi / 3, 0.0]), times)
        rr = model.bodies_at(times, Y)
        return np.column_stack([rr[n][:, k] for n in ["crank", "rod", "piston"] for k in (0, 1)])
    return sc, planar_cols(["crank", "rod", "piston"]), cached(f"slider_crank_bundled_{T}", mk)

def bead_pivot(T=3.0):
    sc = json.load(open(os.path.join(ROOT, "scenes", "bead_slot_through_pivot.json")))
    sc["solve"] = {"t_end": T, "output_step": 0.01}
    M, L, m, g, k = 1.0, 1.0, 0.5, 9.81, 20.0
    JO = M * L * L / 3
    times = np.linspace(0, T, int(round(T * 100)) + 1)
    def mk():
        def rhs(t, y):
            th, thd, r, rd = y
            return [thd, (-2 * m * r * rd * thd - (M * L / 2 + m * r) * g * math.cos(th)) / (JO + m * r * r),
                    rd, r * thd * thd - g * math.sin(th) - k / m * r]
        s = solve_ivp(rhs, (0, T), [0, 0, 0.6, 0], method="DOP853", t_eval=times, rtol=1e-13, atol=1e-13)
        th, r = s.y[0], s.y[2]
        return np.column_stack([L / 2 * np.cos(th), L / 2 * np.sin(th), r * np.cos(th), r * np.sin(th)])
    return sc, planar_cols(["bar", "bead"]), cached(f"bead_pivot_{T}", mk)

MECH["slider_crank"] = slider_crank_bundled
MECH["spherical100"] = lambda: spherical(100.0)
MECH["bead_pivot"] = bead_pivot

if __name__ == "__main__":
    main()
