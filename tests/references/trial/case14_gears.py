"""Case 14: two meshing gears on ground axles, each unbalanced (centre of mass off its axle):
one DOF, theta2 - theta2(0) = -r (theta1 - theta1(0)). Reference: Planar in theta1."""
import math
import numpy as np, sympy as sp
from ref import *

r = 2.0
m1, J1, e1 = 1.0, 0.01, 0.05      # mass, central inertia, COM offset from the axle (body x)
m2, J2, e2 = 0.5, 0.03, 0.08
C1, C2 = (0.0, 0.0), (0.3, 0.0)
th = sp.symbols("th")
a10, a20 = 0.3, -1.0
a2 = a20 - r * (th - a10)
bodies = [("g1", m1, J1, C1[0] + e1 * sp.cos(th), C1[1] + e1 * sp.sin(th), th),
          ("g2", m2, J2, C2[0] + e2 * sp.cos(a2), C2[1] + e2 * sp.sin(a2), a2)]
model = Planar([th], bodies)
times = np.linspace(0, 3.0, 301)
Y = model.solve(np.array([a10, 0.0]), times)
ref = model.bodies_at(times, Y)
def scene():
    bs = []
    for (name, m, J, *_), e, C in zip(bodies, [e1, e2], [C1, C2]):
        x, y, a = ref[name][0]
        bs.append({"name": name, "mass": m, "inertia": J, "points": {"C": [-e, 0.0]}, "position": [float(x), float(y)], "angle": float(a)})
    js = [{"name": "axle1", "type": "revolute", "bodies": ["ground", "g1"], "points": [list(C1), "C"]},
          {"name": "axle2", "type": "revolute", "bodies": ["ground", "g2"], "points": [list(C2), "C"]},
          {"name": "mesh", "type": "gear", "bodies": ["g1", "g2"], "ratio": r}]
    return {"name": "unbalanced_gears", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "solve": {"t_end": 3.0, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}
if __name__ == "__main__":
    trial("unbalanced_gears", scene(), ref)
    sc = scene(); sc["joints"].reverse(); sc["bodies"].reverse()
    trial("unbalanced_gears_reversed", sc, ref, forms=(None,))
