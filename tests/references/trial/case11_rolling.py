"""Case 11: a disc rolling on a fixed inclined rack (rack_pinion with the ground as the rack, the
centre in a slot parallel to the incline), thrown uphill: x(t) = v0 t + a t^2/2 along the incline,
a = g sin(alpha) / (1 + J/(m rho^2)), angle = -x/rho (exact)."""
import math
import numpy as np
from ref import *

al, rho, m = 0.3, 0.1, 2.0
J = 0.5 * m * rho**2
g = 9.81
a = g * math.sin(al) / (1 + J / (m * rho**2))
u = np.array([math.cos(al), -math.sin(al)]); n = np.array([math.sin(al), math.cos(al)])
v0 = -1.0
T = 2.0
times = np.linspace(0, T, 201)
x = v0 * times + 0.5 * a * times**2
ref = {"disc": np.column_stack([rho * n[0] + x * u[0], rho * n[1] + x * u[1], -x / rho])}

def scene():
    return {"name": "rolling_disc_incline", "gravity": [0, -g],
            "bodies": [{"name": "disc", "mass": m, "inertia": J, "position": list(rho * n),
                        "velocity": list(v0 * u), "angular_velocity": -v0 / rho}],
            "joints": [{"name": "track", "type": "slot", "bodies": ["ground", "disc"], "points": [list(rho * n), [0, 0]], "axis": list(u)},
                       {"name": "teeth", "type": "rack_pinion", "bodies": ["disc", "ground"], "points": [[0, 0], [0, 0]],
                        "radius": rho, "axis": list(u)}],
            "outputs": ["energy"],
            "solve": {"t_end": T, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    trial("rolling_disc", scene(), ref)
    sc = scene(); sc["joints"].reverse()
    trial("rolling_disc_reversed", sc, ref, forms=(None,))
