"""Case 15: a five-bar whose couplers line up (its forward-kinematics singularity, where the
couplers' joint can flip between elbow-up and elbow-down) under gravity. Reference: the four link
angles with the loop closure (2 rows) kept by multipliers, regular there."""
import math
import numpy as np, sympy as sp
from ref import *

five = FiveBar(0.4, [0.6, 0.8, 0.8, 0.6], [1.0, 0.5, 0.5, 1.0])
model, bodies = five.model, five.bodies
# crank 1 up-left, crank 4 down-right: the couplers nearly in line along the diagonal
q0 = five.start(math.radians(150), math.radians(-20))
times = np.linspace(0, 3.0, 301)
Y = model.solve(np.array(q0 + [0, 0, 0, 0]), times)
ref = model.bodies_at(times, Y)
cross = np.degrees(np.array([abs(((Y[i, 1] - Y[i, 2]) % (2 * math.pi)) - math.pi) for i in range(len(Y))]))
print("min angle between couplers' lines (deg):", cross.min(), "at t =", times[cross.argmin()])
def scene():
    sc = five.scene("five_bar_singular", {n: ref[n][0] for n in ref},
                    {"t_end": 3.0, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10})
    del sc["dimension"]
    return sc
if __name__ == "__main__":
    trial("fivebar_couplers_aligned", scene(), ref)
