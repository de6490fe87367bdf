"""Case 6a: a Grashof change-point four-bar that is NOT a parallelogram: ground 1.0, crank 0.3,
coupler 0.9, rocker 0.4 (0.3 + 1.0 = 0.9 + 0.4). At crank angle pi every link lies on the ground
line and the two assembly branches cross; the motion continues smoothly onto the other branch.
Reference: minimal coordinate phi with the coupler-rocker joint C = B + a u + h u_perp, where the
signed offset h = sqrt(2 d r (s^2 - (L2-L3)^2)) * sqrt(2) cos(phi/2) / (2 s) is the smooth
continuation through the crossing (s^2 - (L2+L3)^2 = -2 d r (1 + cos phi) vanishes doubly)."""
import math, sys
import numpy as np, sympy as sp
from ref import *

d, r, L2, L3 = 1.0, 0.3, 0.9, 0.4
mc, m2, m3 = 1.0, 0.5, 0.5
phi = sp.symbols("phi")
B = sp.Matrix([r * sp.cos(phi), r * sp.sin(phi)])
D = sp.Matrix([d, 0])
u2 = d**2 + r**2 - 2 * d * r * sp.cos(phi)
s = sp.sqrt(u2)
uh = (D - B) / s
a = (L2**2 - L3**2 + u2) / (2 * s)
h = sp.sqrt(2 * d * r * (u2 - (L2 - L3)**2)) * sp.sqrt(2) * sp.cos(phi / 2) / (2 * s)
C = B + a * uh + h * sp.Matrix([-uh[1], uh[0]])
th2 = sp.atan2(C[1] - B[1], C[0] - B[0])
th3 = sp.atan2(C[1] - D[1], C[0] - D[0])
bodies = [("crank", mc, mc * r**2 / 12, B[0] / 2, B[1] / 2, phi),
          ("coupler", m2, m2 * L2**2 / 12, (B[0] + C[0]) / 2, (B[1] + C[1]) / 2, th2),
          ("rocker", m3, m3 * L3**2 / 12, (D[0] + C[0]) / 2, (D[1] + C[1]) / 2, th3)]
model = Planar([phi], bodies)
# check closure numerically
fC = sp.lambdify(phi, C)
for p in [0.1, 1.0, 2.0, 3.0, math.pi - 1e-3, 4.0, 5.5]:
    c = np.array(fC(p), dtype=float).ravel(); b = np.array([r * math.cos(p), r * math.sin(p)])
    assert abs(np.linalg.norm(c - b) - L2) < 1e-12 and abs(np.linalg.norm(c - [d, 0]) - L3) < 1e-12, p

PHI0, W0 = math.pi / 2, 6.0
T_END = 3.0
times = np.linspace(0, T_END, 301)
Y = model.solve(np.array([PHI0, W0]), times)
ref = model.bodies_at(times, Y)
print("crank turns", (Y[-1, 0] - PHI0) / 2 / math.pi, "omega range", Y[:, 1].min(), Y[:, 1].max())
E = model.energy(times, Y); print("ref energy ptp", np.ptp(E))

def scene(order=None, jorder=None):
    v0 = model.velocities(Y[0])
    bs = []
    for name, L, m in [("crank", r, mc), ("coupler", L2, m2), ("rocker", L3, m3)]:
        x, y, a_ = ref[name][0]
        bs.append({"name": name, "mass": m, "inertia": m * L**2 / 12, "points": bar(L),
                   "position": [float(x), float(y)], "angle": float(a_),
                   "velocity": v0[name][:2], "angular_velocity": v0[name][2]})
    js = [{"name": "A", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], "O"]},
          {"name": "B", "type": "revolute", "bodies": ["crank", "coupler"], "points": ["A", "O"]},
          {"name": "C", "type": "revolute", "bodies": ["coupler", "rocker"], "points": ["A", "A"]},
          {"name": "D", "type": "revolute", "bodies": ["ground", "rocker"], "points": [[d, 0], "O"]}]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "change_point_four_bar", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "outputs": ["energy"], "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    trial("changepoint_fourbar", scene(), ref)
    trial("changepoint_fourbar_reversed", scene([2, 1, 0], [3, 2, 1, 0]), ref, forms=(None,))
