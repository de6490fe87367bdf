import case2_slidercrank as c2
from ref import *
import numpy as np, math
T=10.0
times = np.linspace(0, T, 1001)
Y = c2.model.solve(np.array([c2.PHI0, c2.W0]), times)
ref = c2.model.bodies_at(times, Y)
for f in [None, "ggl", "partitioned"]:
    sc = c2.scene("prismatic"); sc["solve"]["t_end"] = T
    res = run(sc, "sc10", f); d = res["data"]; h = res["header"]; s = res["summary"]
    e = np.abs(d[:, h.index("crank.angle")] - ref["crank"][:, 2])
    print(f, s["steps"], f"max {e.max():.2e}", " ".join(f"{d[i,0]:.0f}:{e[i]:.1e}" for i in range(0,1001,100)), "drift", s["energy_drift"], s["warnings"][:2])
