from case2_slidercrank import *
sc = scene("prismatic")
res = run(sc, "sc_prof", None)
d = res["data"]; h = res["header"]; ic = h.index("crank.angle")
ea = d[:, ic] - ref["crank"][:, 2]
for i in range(0, 301, 10):
    print(f"t={d[i,0]:.2f} err={ea[i]:+.2e} phi={ref['crank'][i,2]%(2*math.pi):.2f} w={Y[i,1]:.2f}")
