"""Case 17: centrifugal pendulum: a spindle driven at constant spin w about the vertical (hinge
to the ground + angular_velocity driver), an arm (bar, moments [Ja, J, J]) hinged at the spindle's
top about a horizontal axis fixed in the spindle. With theta from the downward vertical:
(m lc^2 + J) theta'' = w^2 (m lc^2 + J - Ja) sin cos - m g lc sin (exact 1-DOF)."""
import math
import numpy as np
from scipy.integrate import solve_ivp
from ref import *

w, m, lc, Ja, J, h = 4.0, 0.8, 0.25, 0.002, 0.02, 0.5
g = 9.81
th0 = 0.5
Jp = m * lc**2 + J
def rhs(t, y):
    return [y[1], (w**2 * (Jp - Ja) * math.sin(y[0]) * math.cos(y[0]) - m * g * lc * math.sin(y[0])) / Jp]
T = 3.0
times = np.linspace(0, T, 301)
s = solve_ivp(rhs, (0, T), [th0, 0.0], t_eval=times, method="DOP853", rtol=1e-12, atol=1e-12)
th, ps = s.y[0], w * times
C = np.column_stack([lc * np.sin(th) * np.cos(ps), lc * np.sin(th) * np.sin(ps), h - lc * np.cos(th)])
print("theta range", th.min(), th.max())
beta = math.pi / 2 - th0
Rt = np.array([[math.cos(beta), 0, math.sin(beta)], [0, 1, 0], [-math.sin(beta), 0, math.cos(beta)]])
wb = Rt.T @ np.array([0, 0, w])
def scene():
    return {"name": "centrifugal_pendulum", "dimension": 3, "gravity": [0, 0, -g],
            "bodies": [{"name": "spindle", "mass": 2.0, "inertia": [0.01, 0.01, 0.02], "points": {"B": [0, 0, -h / 2], "T": [0, 0, h / 2]},
                        "position": [0, 0, h / 2], "angular_velocity": [0, 0, w]},
                       {"name": "arm", "mass": m, "inertia": [Ja, J, J], "points": {"P": [-lc, 0, 0]},
                        "position": list(C[0]), "cardan": [0, beta, 0], "angular_velocity": list(wb),
                        "velocity": [0, w * lc * math.sin(th0), 0]}],
            "joints": [{"name": "bearing", "type": "revolute", "bodies": ["ground", "spindle"], "points": [[0, 0, 0], "B"], "axis": [0, 0, 1]},
                       {"name": "pivot", "type": "revolute", "bodies": ["spindle", "arm"], "points": ["T", "P"], "axis": [0, 1, 0]}],
            "drivers": [{"name": "motor", "joint": "bearing", "angular_velocity": w}],
            "solve": {"t_end": T, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}
if __name__ == "__main__":
    for f in [None, "ggl", "partitioned"]:
        res = run(scene(), "centrifugal", f); d, hh = res["data"], res["header"]; s_ = res["summary"] or {}
        if d is None or not len(d): print(f, res["rc"], res["stderr"][:400]); continue
        X = d[:, [hh.index("arm.x"), hh.index("arm.y"), hh.index("arm.z")]]
        print(f, res["rc"], s_.get("formulation"), s_.get("steps"), f"pos err {np.max(np.abs(X - C[:len(X)])):.2e}", s_.get("warnings", [])[:3], res["stderr"][:300] if res["rc"] else "")
