"""Case 3: several bodies on ONE pin.
(a) star: bar A pinned to ground at O, bars B and C both hinged at A's free end P (three bodies
    share P), written three ways: A-B and A-C; A-B and B-C; A-C and C-B.
(b) three bars all pinned to the ground at the same ground point (three independent pendulums).
(c) a point mass K (inertia 0) hinged to two bars at once: bar1 pinned to ground, K at bar1's
    end, bar2 hinged to K (a double pendulum whose knee is a point mass)."""
import math, sys
import numpy as np, sympy as sp
from ref import *

LA, LB, LC = 1.0, 0.8, 0.6
mA, mB, mC = 1.0, 0.7, 0.5
a, b, c = sp.symbols("a b c")
P = sp.Matrix([LA * sp.cos(a), LA * sp.sin(a)])
star_bodies = [
    ("A", mA, mA * LA**2 / 12, LA / 2 * sp.cos(a), LA / 2 * sp.sin(a), a),
    ("B", mB, mB * LB**2 / 12, P[0] + LB / 2 * sp.cos(b), P[1] + LB / 2 * sp.sin(b), b),
    ("C", mC, mC * LC**2 / 12, P[0] + LC / 2 * sp.cos(c), P[1] + LC / 2 * sp.sin(c), c),
]
star = Planar([a, b, c], star_bodies)
T_END = 3.0
times = np.linspace(0, T_END, 301)
Y0 = np.array([0.0, -0.5, 1.0, 0.0, 0.0, 0.0])
Ys = star.solve(Y0, times)
ref_star = star.bodies_at(times, Ys)

def placed(ref, name, L, m):
    x, y, th = ref[name][0]
    return {"name": name, "mass": m, "inertia": m * L**2 / 12, "points": bar(L),
            "position": [float(x), float(y)], "angle": float(th)}

def solve_(t=T_END):
    return {"t_end": t, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}

def star_scene(variant, order=None, jorder=None):
    bs = [placed(ref_star, "A", LA, mA), placed(ref_star, "B", LB, mB), placed(ref_star, "C", LC, mC)]
    pins = {"AB+AC": [("A", "B"), ("A", "C")], "AB+BC": [("A", "B"), ("B", "C")],
            "AC+CB": [("A", "C"), ("C", "B")], "BA+CA": [("B", "A"), ("C", "A")]}[variant]
    pt = {("A", "B"): ["A", "O"], ("A", "C"): ["A", "O"], ("B", "C"): ["O", "O"], ("C", "B"): ["O", "O"],
          ("B", "A"): ["O", "A"], ("C", "A"): ["O", "A"]}
    js = [{"name": "O", "type": "revolute", "bodies": ["ground", "A"], "points": [[0.0, 0.0], "O"]}]
    for i, (p, q) in enumerate(pins):
        js.append({"name": f"P{i}", "type": "revolute", "bodies": [p, q], "points": pt[(p, q)]})
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "star", "gravity": [0.0, -9.81], "bodies": bs, "joints": js, "solve": solve_()}

# (b) three bars on the same ground point
th = sp.symbols("t1 t2 t3")
fan_b = [(f"F{i}", 1.0 + 0.3 * i, (1.0 + 0.3 * i) * (0.5 + 0.2 * i)**2 / 12,
          (0.5 + 0.2 * i) / 2 * sp.cos(th[i]), (0.5 + 0.2 * i) / 2 * sp.sin(th[i]), th[i]) for i in range(3)]
fan = Planar(list(th), fan_b)
Yf = fan.solve(np.array([0.3, -1.0, 2.5, 0, 0, 0]), times)
ref_fan = fan.bodies_at(times, Yf)
def fan_scene():
    bs = [placed(ref_fan, f"F{i}", 0.5 + 0.2 * i, 1.0 + 0.3 * i) for i in range(3)]
    js = [{"name": f"pin{i}", "type": "revolute", "bodies": ["ground", f"F{i}"], "points": [[0.0, 0.0], "O"]} for i in range(3)]
    return {"name": "fan", "gravity": [0.0, -9.81], "bodies": bs, "joints": js, "solve": solve_()}

# (c) point-mass knee
L1, L2, m1, m2, mk = 1.0, 0.7, 1.0, 0.6, 0.8
t1, t2 = sp.symbols("t1 t2")
K = sp.Matrix([L1 * sp.cos(t1), L1 * sp.sin(t1)])
knee_b = [("bar1", m1, m1 * L1**2 / 12, L1 / 2 * sp.cos(t1), L1 / 2 * sp.sin(t1), t1),
          ("K", mk, 0.0, K[0], K[1], sp.Float(0.0)),
          ("bar2", m2, m2 * L2**2 / 12, K[0] + L2 / 2 * sp.cos(t2), K[1] + L2 / 2 * sp.sin(t2), t2)]
knee = Planar([t1, t2], knee_b)
Yk = knee.solve(np.array([0.0, 0.4, 0.0, 0.0]), times)
ref_knee = knee.bodies_at(times, Yk)
def knee_scene(order=None, jorder=None, pts="named"):
    bs = [placed(ref_knee, "bar1", L1, m1),
          {"name": "K", "mass": mk, "inertia": 0.0, "position": [float(ref_knee["K"][0][0]), float(ref_knee["K"][0][1])]},
          placed(ref_knee, "bar2", L2, m2)]
    js = [{"name": "shoulder", "type": "revolute", "bodies": ["ground", "bar1"], "points": [[0.0, 0.0], "O"]},
          {"name": "k1", "type": "revolute", "bodies": ["bar1", "K"], "points": ["A", [0.0, 0.0]]},
          {"name": "k2", "type": "revolute", "bodies": ["K", "bar2"], "points": [[0.0, 0.0], "O"]}]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "knee", "gravity": [0.0, -9.81], "bodies": bs, "joints": js, "solve": solve_()}

if __name__ == "__main__":
    for v in ["AB+AC", "AB+BC", "AC+CB", "BA+CA"]:
        trial(f"star_{v}", star_scene(v), ref_star, forms=(None, "ggl", "partitioned") if v == "AB+AC" else (None,))
    trial("star_AB+BC_shuffled", star_scene("AB+BC", order=[2, 0, 1], jorder=[2, 0, 1]), ref_star, forms=(None,))
    trial("fan", fan_scene(), ref_fan)
    trial("knee", knee_scene(), ref_knee, skip=("K",))
    trial("knee_reversed", knee_scene(order=[2, 1, 0], jorder=[2, 1, 0]), ref_knee, forms=(None,), skip=("K",))
