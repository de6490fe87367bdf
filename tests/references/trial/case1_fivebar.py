"""Case 1: planar five-bar (2 DOF), gravity, released from rest, 3 s."""
import math, sys
import numpy as np, sympy as sp
from ref import *

d, L1, L2, L3, L4 = 1.2, 0.5, 1.2, 1.2, 0.5
m = {"c1": 1.0, "k2": 1.5, "k3": 1.5, "c4": 1.0}
q1, q4 = sp.symbols("q1 q4")
B = sp.Matrix([L1 * sp.cos(q1), L1 * sp.sin(q1)])
D = sp.Matrix([d + L4 * sp.cos(q4), L4 * sp.sin(q4)])
BD = D - B
s = sp.sqrt(BD.dot(BD))
u = BD / s
a = (L2**2 - L3**2 + s**2) / (2 * s)
h = sp.sqrt(L2**2 - a**2)
C = B + a * u + h * sp.Matrix([-u[1], u[0]])  # left of B->D
th2 = sp.atan2(C[1] - B[1], C[0] - B[0])
th3 = sp.atan2(C[1] - D[1], C[0] - D[0])
bodies = [
    ("c1", m["c1"], m["c1"] * L1**2 / 12, L1 / 2 * sp.cos(q1), L1 / 2 * sp.sin(q1), q1),
    ("k2", m["k2"], m["k2"] * L2**2 / 12, (B[0] + C[0]) / 2, (B[1] + C[1]) / 2, th2),
    ("k3", m["k3"], m["k3"] * L3**2 / 12, (D[0] + C[0]) / 2, (D[1] + C[1]) / 2, th3),
    ("c4", m["c4"], m["c4"] * L4**2 / 12, d + L4 / 2 * sp.cos(q4), L4 / 2 * sp.sin(q4), q4),
]
model = Planar([q1, q4], bodies)
Q0 = [math.radians(-20.0), math.radians(-150.0)]
T_END = 3.0
times = np.linspace(0, T_END, 301)
Y = model.solve(np.array(Q0 + [0.0, 0.0]), times)
ref = model.bodies_at(times, Y)
E = model.energy(times, Y)
print("ref energy drift", np.max(np.abs(E - E[0])))
# minimum transmission: h over run
st = ref  # initial
def body(name, L, mass, i):
    x, y, th = ref[name][0]
    return {"name": name, "mass": mass, "inertia": mass * L**2 / 12, "points": bar(L),
            "position": [float(x), float(y)], "angle": float(th)}

def scene(order=None, jorder=None):
    bs = [body("c1", L1, 1.0, 0), body("k2", L2, 1.5, 1), body("k3", L3, 1.5, 2), body("c4", L4, 1.0, 3)]
    js = [
        {"name": "A", "type": "revolute", "bodies": ["ground", "c1"], "points": [[0.0, 0.0], "O"]},
        {"name": "B", "type": "revolute", "bodies": ["c1", "k2"], "points": ["A", "O"]},
        {"name": "C", "type": "revolute", "bodies": ["k2", "k3"], "points": ["A", "A"]},
        {"name": "D", "type": "revolute", "bodies": ["k3", "c4"], "points": ["O", "A"]},
        {"name": "E", "type": "revolute", "bodies": ["ground", "c4"], "points": [[d, 0.0], "O"]},
    ]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "five_bar", "dimension": 2, "gravity": [0.0, -9.81], "bodies": bs, "joints": js,
            "outputs": ["energy"],
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    trial("fivebar", scene(), ref)
    trial("fivebar_reversed", scene(order=[3, 2, 1, 0], jorder=[4, 3, 2, 1, 0]), ref, forms=(None,))
    trial("fivebar_shuffled", scene(order=[2, 0, 3, 1], jorder=[2, 4, 0, 3, 1]), ref, forms=(None,))
    sc = scene(); sc["solve"]["rtol"] = 1e-10; sc["solve"]["atol"] = 1e-12
    trial("fivebar_rtol1e-10", sc, ref, forms=(None,))
