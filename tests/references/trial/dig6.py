from case6_changepoint import *
for rt in [1e-8, 1e-10, 1e-12]:
  for f in [None, "ggl", "partitioned"]:
    sc = scene(); sc["solve"]["rtol"] = rt; sc["solve"]["atol"] = rt*1e-2
    res = run(sc, f"cp{rt}", f)
    dd = res["data"]; hh = res["header"]; ic = hh.index("crank.angle"); ie = hh.index("energy")
    err = dd[:, ic] - ref["crank"][:, 2]
    s = res["summary"]
    print(rt, f, s["steps"], f"max {np.abs(err).max():.2e}", " ".join(f"{dd[i,0]:.1f}:{err[i]:+.1e}/{dd[i,ie]-E[0]:+.1e}" for i in range(0, 301, 30)))
