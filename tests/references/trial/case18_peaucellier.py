"""Case 18: Peaucellier-Lipkin straight-line linkage: 7 bars, three bodies on each of the pins
A, B, C, gravity, released from rest; the reference (PinModel) covers 0.3 s: from t = 0.40 the
rhombus folds and the reference integrator stalls there. The point P must stay on the line x = (l^2 - s^2)/(2 r)
exactly; reference: the 7 link angles with 3 loop closures (6 rows) by multipliers."""
import math
import numpy as np, sympy as sp
from ref import *

l, s, r = 1.0, 0.4, 0.5
O, O1 = np.array([0.0, 0.0]), np.array([r, 0.0])
XLINE = (l * l - s * s) / (2 * r)
names = ["OA", "OB", "AC", "CB", "BP", "PA", "crank"]
lens = {"OA": l, "OB": l, "AC": s, "CB": s, "BP": s, "PA": s, "crank": r}
mass = {n: 0.5 + 0.5 * lens[n] for n in names}
def assemble(phi):
    Cn = O1 + r * np.array([math.cos(phi), math.sin(phi)])
    dC = np.linalg.norm(Cn); e = Cn / dC; nrm = np.array([-e[1], e[0]])
    a = (l * l - s * s + dC * dC) / (2 * dC); h = math.sqrt(l * l - a * a)
    An, Bn = a * e + h * nrm, a * e - h * nrm
    Pn = e * (l * l - s * s) / dC
    ang = lambda v: math.atan2(v[1], v[0])
    return [ang(An), ang(Bn), ang(Cn - An), ang(Bn - Cn), ang(Pn - Bn), ang(An - Pn), phi], Pn

q0, P0 = assemble(0.8)
idx = {n: i for i, n in enumerate(names)}
h = {n: lens[n] / 2 for n in names}
pins = [(None, (0, 0), idx["OA"], (-h["OA"], 0)), (None, (0, 0), idx["OB"], (-h["OB"], 0)),
        (None, tuple(O1), idx["crank"], (-h["crank"], 0)),
        (idx["OA"], (h["OA"], 0), idx["AC"], (-h["AC"], 0)), (idx["OA"], (h["OA"], 0), idx["PA"], (h["PA"], 0)),
        (idx["OB"], (h["OB"], 0), idx["CB"], (h["CB"], 0)), (idx["OB"], (h["OB"], 0), idx["BP"], (-h["BP"], 0)),
        (idx["AC"], (h["AC"], 0), idx["CB"], (-h["CB"], 0)), (idx["crank"], (h["crank"], 0), idx["AC"], (h["AC"], 0)),
        (idx["BP"], (h["BP"], 0), idx["PA"], (-h["PA"], 0))]
model = PinModel([(mass[n], mass[n] * lens[n]**2 / 12) for n in names], pins)
# start: each bar from its O end (the first-listed point of its pins) along its angle
starts = {"OA": O, "OB": O, "crank": O1}
T = 0.3
times = np.linspace(0, T, 31)
ang = dict(zip(names, q0))
An = l * np.array([math.cos(ang["OA"]), math.sin(ang["OA"])]); Bn = l * np.array([math.cos(ang["OB"]), math.sin(ang["OB"])])
starts.update({"AC": An, "CB": An + s * np.array([math.cos(ang["AC"]), math.sin(ang["AC"])]), "BP": Bn, "PA": P0})
z0 = []
for n in names:
    c = starts[n] + h[n] * np.array([math.cos(ang[n]), math.sin(ang[n])]); z0 += [c[0], c[1], ang[n]]
# check the start closes every pin
def pin_err(z):
    e = 0
    for a, sa, b, sb in pins:
        R = lambda th, v: np.array([math.cos(th) * v[0] - math.sin(th) * v[1], math.sin(th) * v[0] + math.cos(th) * v[1]])
        pa = np.array(sa, float) if a is None else z[3 * a:3 * a + 2] + R(z[3 * a + 2], sa)
        pb = z[3 * b:3 * b + 2] + R(z[3 * b + 2], sb)
        e = max(e, np.max(np.abs(pa - pb)))
    return e
print("pins at start", pin_err(np.array(z0)))
Z = model.solve(np.array(z0), times)
print("pins at end", pin_err(Z[-1]), "crank range", Z[:, 3 * idx["crank"] + 2].min(), Z[:, 3 * idx["crank"] + 2].max(), "(limits +-1.855)")
ref = {n: Z[:, 3 * i:3 * i + 3] for i, n in enumerate(names)}

def scene():
    bs = []
    for n in names:
        x, y, a = ref[n][0]
        bs.append({"name": n, "mass": mass[n], "inertia": mass[n] * lens[n]**2 / 12, "points": bar(lens[n]),
                   "position": [float(x), float(y)], "angle": float(a)})
    J = lambda nm, a, b, pa, pb: {"name": nm, "type": "revolute", "bodies": [a, b], "points": [pa, pb]}
    js = [J("O_a", "ground", "OA", [0, 0], "O"), J("O_b", "ground", "OB", [0, 0], "O"),
          J("O1", "ground", "crank", list(O1), "O"),
          J("A_ac", "OA", "AC", "A", "O"), J("A_pa", "OA", "PA", "A", "A"),
          J("B_cb", "OB", "CB", "A", "A"), J("B_bp", "OB", "BP", "A", "O"),
          J("C_ac", "AC", "CB", "A", "O"), J("C_crank", "crank", "AC", "A", "A"),
          J("P", "BP", "PA", "A", "O")]
    return {"name": "peaucellier", "gravity": [0, -9.81], "bodies": bs, "joints": js, "outputs": ["PA.O"],
            "solve": {"t_end": T, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    out = trial("peaucellier", scene(), ref)
    for f, v in out.items():
        res = v[2]
        if res["data"] is not None and len(res["data"]):
            h = res["header"]; px = res["data"][:, h.index("PA.O.x")]
            print(f"   {f or 'default'}: P off its line by {np.max(np.abs(px - XLINE)):.2e}")
