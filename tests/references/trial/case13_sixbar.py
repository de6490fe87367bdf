"""Case 13: Watt II six-bar (two four-bar loops in series sharing a ternary rocker), gravity,
released from rest. Reference: the five link angles with the two loop closures (4 rows) kept by
multipliers (PlanarConstrained), DOP853 at 1e-12."""
import math
import numpy as np, sympy as sp
from scipy.optimize import fsolve
from ref import *

A, D, G5 = (0.0, 0.0), (1.0, 0.0), (1.9, -0.3)
L1, L2, L3, L4, L5 = 0.4, 1.0, 0.8, 0.9, 0.7
e3 = (-0.3, 0.25)       # point E on the ternary rocker, in its frame (x from D to C)
m = [0.8, 1.0, 1.2, 0.9, 0.7]
t = sp.symbols("t1:6")
u = lambda a: sp.Matrix([sp.cos(a), sp.sin(a)])
B = sp.Matrix(A) + L1 * u(t[0])
C = B + L2 * u(t[1])
R3 = sp.Matrix([[sp.cos(t[2]), -sp.sin(t[2])], [sp.sin(t[2]), sp.cos(t[2])]])
E = sp.Matrix(D) + R3 * sp.Matrix(e3)
F = E + L4 * u(t[3])
cons = list(C - (sp.Matrix(D) + L3 * u(t[2]))) + list(F - (sp.Matrix(G5) + L5 * u(t[4])))
c3 = sp.Matrix(D) + R3 * sp.Matrix([L3 / 2, 0])  # rocker's centre: the bar D-C; E is an extra point on it
bodies = [("crank", m[0], m[0] * L1**2 / 12, *(sp.Matrix(A) + L1 / 2 * u(t[0])), t[0]),
          ("coupler", m[1], m[1] * L2**2 / 12, *(B + L2 / 2 * u(t[1])), t[1]),
          ("rocker", m[2], m[2] * L3**2 / 12, *c3, t[2]),
          ("link4", m[3], m[3] * L4**2 / 12, *(E + L4 / 2 * u(t[3])), t[3]),
          ("link5", m[4], m[4] * L5**2 / 12, *(sp.Matrix(G5) + L5 / 2 * u(t[4])), t[4])]
model = PlanarConstrained(list(t), bodies, cons)
# assemble at crank angle 60 deg
fc = sp.lambdify(t, cons)
th1 = math.radians(60)
sol = fsolve(lambda x: np.array(fc(th1, *x), dtype=float).ravel(), [math.radians(20), math.radians(70), math.radians(-20), math.radians(100)], xtol=1e-15)
q0 = np.array([th1, *sol])
print("closure", np.max(np.abs(np.array(fc(*q0), dtype=float))), "angles", np.degrees(q0))
T_END = 3.0
times = np.linspace(0, T_END, 301)
Y = model.solve(np.concatenate([q0, np.zeros(5)]), times)
ref = model.bodies_at(times, Y)

def scene(order=None, jorder=None):
    bs = []
    for (name, mm, I, *_), L in zip(bodies, [L1, L2, L3, L4, L5]):
        x, y, a = ref[name][0]
        pts = bar(L)
        if name == "rocker":
            pts["E"] = [e3[0] - L3 / 2, e3[1]]
        bs.append({"name": name, "mass": mm, "inertia": I, "points": pts, "position": [float(x), float(y)], "angle": float(a)})
    js = [{"name": "jA", "type": "revolute", "bodies": ["ground", "crank"], "points": [list(A), "O"]},
          {"name": "jB", "type": "revolute", "bodies": ["crank", "coupler"], "points": ["A", "O"]},
          {"name": "jC", "type": "revolute", "bodies": ["coupler", "rocker"], "points": ["A", "A"]},
          {"name": "jD", "type": "revolute", "bodies": ["ground", "rocker"], "points": [list(D), "O"]},
          {"name": "jE", "type": "revolute", "bodies": ["rocker", "link4"], "points": ["E", "O"]},
          {"name": "jF", "type": "revolute", "bodies": ["link4", "link5"], "points": ["A", "A"]},
          {"name": "jG", "type": "revolute", "bodies": ["ground", "link5"], "points": [list(G5), "O"]}]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "watt_six_bar", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    trial("watt_sixbar", scene(), ref)
    trial("watt_sixbar_shuffled", scene([4, 2, 0, 3, 1], [6, 3, 0, 5, 2, 4, 1]), ref, forms=(None,))
