from case2_slidercrank import *
for rt in [1e-6, 1e-8, 1e-10]:
    for f in [None, "ggl", "partitioned"]:
        sc = scene("prismatic"); sc["solve"]["rtol"] = rt; sc["solve"]["atol"] = rt*1e-2
        res = run(sc, f"sc_rt{rt}", f)
        d = res["data"]; h = res["header"]
        ic = h.index("crank.angle"); ip = h.index("piston.x")
        ea = np.abs(d[:, ic] - ref["crank"][:, 2]); ex = np.abs(d[:, ip]-ref["piston"][:,0])
        s = res["summary"]
        print(f"rtol {rt:g} {f or 'default':12s} steps {s['steps']:5d} crank err max {ea.max():.2e} at t={d[ea.argmax(),0]:.2f}; t=1:{ea[100]:.1e} t=2:{ea[200]:.1e}; piston {ex.max():.2e} drift {s['energy_drift']:.1e} cpu {s['cpu_seconds']:.3f}")
