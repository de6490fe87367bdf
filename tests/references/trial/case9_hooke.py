"""Case 9: Hooke's joint driveshaft as a user writes it: both shafts in their own bearings
(spatial hinges to the ground) and the cross between them (redundant rows). (a) input shaft driven
at 3 rad/s: tan th2 = tan th1 / cos beta (exact); (b) free-spinning: 1-DOF reference
T = 1/2 (J1 + J2 (dth2/dth1)^2) th1'^2."""
import math, sys
import numpy as np, sympy as sp
from ref import *

beta = 0.5
Jax, Jt = 0.002, 0.03
dvec = [math.cos(beta), math.sin(beta), 0.0]
T_END = 3.0
times = np.linspace(0, T_END, 301)

def scene(driven=True):
    w2 = 3.0 / math.cos(beta)
    sc = {"name": "driveshaft", "dimension": 3,
          "bodies": [{"name": "shaft1", "mass": 1.0, "inertia": [Jax, Jt, Jt], "points": {"B": [0, 0, 0], "U": [0.3, 0, 0]},
                      "position": [-0.3, 0, 0], "angular_velocity": [3.0, 0, 0]},
                     {"name": "shaft2", "mass": 1.0, "inertia": [Jax, Jt, Jt], "points": {"B": [0, 0, 0], "U": [-0.3, 0, 0]},
                      "position": [0.3 * dvec[0], 0.3 * dvec[1], 0.0], "cardan": [beta, 0, 0], "angular_velocity": [w2, 0, 0]}],
          "joints": [{"name": "bearing1", "type": "revolute", "bodies": ["ground", "shaft1"], "points": [[-0.3, 0, 0], "B"], "axis": [1, 0, 0]},
                     {"name": "bearing2", "type": "revolute", "bodies": ["ground", "shaft2"], "points": [[0.3 * dvec[0], 0.3 * dvec[1], 0.0], "B"], "axis": dvec},
                     {"name": "cross", "type": "universal", "bodies": ["shaft1", "shaft2"], "points": ["U", "U"], "axes": [[0, 1, 0], [0, 0, 1]]}],
          "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}
    if driven:
        sc["drivers"] = [{"name": "motor", "joint": "bearing1", "angular_velocity": 3.0}]
    return sc

def phis(res):
    d, h = res["data"], res["header"]
    return d[:, 0], d[:, h.index("shaft1.phi")], d[:, h.index("shaft2.phi")]

def check(tag, sc, th1_ref, th2_ref, forms=(None, "ggl", "partitioned")):
    for f in forms:
        res = run(sc, tag, f); s = res["summary"] or {}
        if res["data"] is None or len(res["data"]) == 0:
            print(tag, f, "rc", res["rc"], res["stderr"][:500]); continue
        t, p1, p2 = phis(res)
        n = len(t)
        e1 = np.max(np.abs(wrap(p1 - th1_ref[:n]))); e2 = np.max(np.abs(wrap(p2 - th2_ref[:n])))
        print(f"{tag+'['+(f or 'default')+']':34s} rc={res['rc']} form={s.get('formulation')} steps={s.get('steps')} t={s.get('t_reached')} "
              f"th1 err {e1:.2e} th2 err {e2:.2e} drift={s.get('energy_drift')} redundant={s.get('redundant_joints')}")
        for w in (s.get("warnings") or [])[:4]: print("     warning:", w[:250])
        if res["rc"]: print("     stderr:", res["stderr"][:600])

if __name__ == "__main__":
    th1 = 3.0 * times
    th2 = np.arctan2(np.sin(th1), math.cos(beta) * np.cos(th1))
    check("driveshaft_driven", scene(True), th1, th2)
    q = sp.symbols("q")
    t2 = sp.atan2(sp.sin(q), math.cos(beta) * sp.cos(q))
    m = Planar([q], [("s1", 1.0, Jax, sp.Float(0), sp.Float(0), q), ("s2", 1.0, Jax, sp.Float(0), sp.Float(0), t2)], g=0.0)
    Y = m.solve(np.array([0.0, 3.0]), times)
    r = m.bodies_at(times, Y)
    check("driveshaft_free", scene(False), r["s1"][:, 2], r["s2"][:, 2])
