from case6_changepoint import *
import sys
rt=float(sys.argv[1]); f=sys.argv[2] if len(sys.argv)>2 else None
sc = scene(); sc["solve"]["rtol"] = rt; sc["solve"]["atol"] = float(sys.argv[3]) if len(sys.argv)>3 else rt*1e-2
res = run(sc, f"cp{rt}", f)
print(res["cmd"]); print(res["rc"], res["stderr"][:3000]); s=res["summary"]; print({k:s[k] for k in ["formulation","steps","t_reached","completed","stopped_by"]})
