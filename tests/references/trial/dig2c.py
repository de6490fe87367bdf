from case2_slidercrank import *
for f, ei in [(None,"always"),(None,"never"),("index1","auto"),("compliant_ggl","auto")]:
    sc = scene("prismatic"); sc["solve"]["energy_invariant"]=ei
    res = run(sc, "sc_ei", f)
    d = res["data"]; h = res["header"]; ic = h.index("crank.angle")
    ea = np.abs(d[:, ic] - ref["crank"][:, 2]); s=res["summary"]
    print(f, ei, s["formulation"], s["steps"], f"{ea.max():.2e}", s["energy_drift"], s.get("warnings"))
