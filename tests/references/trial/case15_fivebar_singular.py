"""Case 15: a five-bar whose couplers line up (its forward-kinematics singularity, where the
couplers' joint can flip between elbow-up and elbow-down) under gravity. Reference: the four link
angles with the loop closure (2 rows) kept by multipliers, regular there."""
import math
import numpy as np, sympy as sp
from ref import *

d, L1, L2, L3, L4 = 0.4, 0.6, 0.8, 0.8, 0.6
m = [1.0, 0.5, 0.5, 1.0]
t = sp.symbols("t1:5")
u = lambda a: sp.Matrix([sp.cos(a), sp.sin(a)])
B = L1 * u(t[0]); Dp = sp.Matrix([d, 0]) + L4 * u(t[3])
C2 = B + L2 * u(t[1]); C3 = Dp + L3 * u(t[2])
cons = list(C2 - C3)
bodies = [("c1", m[0], m[0] * L1**2 / 12, *(L1 / 2 * u(t[0])), t[0]),
          ("k2", m[1], m[1] * L2**2 / 12, *(B + L2 / 2 * u(t[1])), t[1]),
          ("k3", m[2], m[2] * L3**2 / 12, *(Dp + L3 / 2 * u(t[2])), t[2]),
          ("c4", m[3], m[3] * L4**2 / 12, *(sp.Matrix([d, 0]) + L4 / 2 * u(t[3])), t[3])]
model = PlanarConstrained(list(t), bodies, cons)
def start(q1, q4, up=True):
    b = np.array([L1 * math.cos(q1), L1 * math.sin(q1)]); dd = np.array([d + L4 * math.cos(q4), L4 * math.sin(q4)])
    s = np.linalg.norm(dd - b); uu = (dd - b) / s; a = (L2**2 - L3**2 + s**2) / (2 * s); h = math.sqrt(L2**2 - a**2)
    c = b + a * uu + (1 if up else -1) * h * np.array([-uu[1], uu[0]])
    return [q1, math.atan2(*(c - b)[::-1]), math.atan2(*(c - dd)[::-1]), q4]
# crank 1 up-left, crank 4 down-right: the couplers nearly in line along the diagonal
q0 = start(math.radians(150), math.radians(-20))
times = np.linspace(0, 3.0, 301)
Y = model.solve(np.array(q0 + [0, 0, 0, 0]), times)
ref = model.bodies_at(times, Y)
cross = np.degrees(np.array([abs(((Y[i, 1] - Y[i, 2]) % (2 * math.pi)) - math.pi) for i in range(len(Y))]))
print("min angle between couplers' lines (deg):", cross.min(), "at t =", times[cross.argmin()])
def scene():
    bs = []
    for (name, mm, I, *_), L in zip(bodies, [L1, L2, L3, L4]):
        x, y, a = ref[name][0]
        bs.append({"name": name, "mass": mm, "inertia": I, "points": bar(L), "position": [float(x), float(y)], "angle": float(a)})
    js = [{"name": "A", "type": "revolute", "bodies": ["ground", "c1"], "points": [[0, 0], "O"]},
          {"name": "B", "type": "revolute", "bodies": ["c1", "k2"], "points": ["A", "O"]},
          {"name": "C", "type": "revolute", "bodies": ["k2", "k3"], "points": ["A", "A"]},
          {"name": "D", "type": "revolute", "bodies": ["k3", "c4"], "points": ["O", "A"]},
          {"name": "E", "type": "revolute", "bodies": ["ground", "c4"], "points": [[d, 0], "O"]}]
    return {"name": "five_bar_singular", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "solve": {"t_end": 3.0, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}
if __name__ == "__main__":
    trial("fivebar_couplers_aligned", scene(), ref)
