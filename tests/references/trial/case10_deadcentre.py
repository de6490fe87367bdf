"""Case 10: the offset slider-crank of case 2 started exactly at its dead centres at rest (gravity
only), and an ordinary 4-bar with its crank in line with the coupler at the start."""
import math
import numpy as np
import case2_slidercrank as c2
from ref import *

r, l, e = c2.r, c2.l, c2.e
times = np.linspace(0, 3.0, 301)
for tag, dist in [("outer_dead_centre", r + l), ("inner_dead_centre", l - r)]:
    # crank and rod on the line from O to the wrist pin P = (xP, e)
    xP = math.sqrt(dist**2 - e**2)
    ang = math.atan2(e, xP)
    phi0 = ang if tag.startswith("outer") else ang + math.pi
    Y = c2.model.solve(np.array([phi0, 0.0]), times)
    c2.PHI0, c2.W0, c2.Y = phi0, 0.0, Y
    c2.ref = c2.model.bodies_at(times, Y)
    sc = c2.scene("prismatic", with_vel=False)
    print(f"-- {tag}: phi0 = {phi0:.6f}, crank range [{Y[:,0].min():.3f}, {Y[:,0].max():.3f}]")
    trial(f"slidercrank_{tag}", sc, c2.ref, skip=("piston",))
