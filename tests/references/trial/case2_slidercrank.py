"""Case 2: offset slider-crank, gravity only, piston a point mass, rod with an offset (bent) centre,
crank spinning over the top so that it passes both dead centres repeatedly."""
import math, sys
import numpy as np, sympy as sp
from ref import *

r, l, e = 0.15, 0.5, 0.08        # crank, rod (pin to pin), slider line y = e (eccentric)
mc, mr, mp = 1.0, 0.6, 0.4
Ic, Ir = mc * r**2 / 12, 0.02
cA = (0.2, 0.04)                 # rod centre of mass relative to the crank pin, rod frame (x along A->B)
phi = sp.symbols("phi")
A = sp.Matrix([r * sp.cos(phi), r * sp.sin(phi)])
xP = A[0] + sp.sqrt(l**2 - (e - A[1])**2)
psi = sp.atan2(e - A[1], xP - A[0])
G = A + sp.Matrix([[sp.cos(psi), -sp.sin(psi)], [sp.sin(psi), sp.cos(psi)]]) * sp.Matrix(cA)
bodies = [
    ("crank", mc, Ic, r / 2 * sp.cos(phi), r / 2 * sp.sin(phi), phi),
    ("rod", mr, Ir, G[0], G[1], psi),
    ("piston", mp, 0.0, xP, sp.Float(e), sp.Float(0.0)),
]
model = Planar([phi], bodies)
PHI0, W0 = math.pi / 2, 4.0
T_END = 3.0
times = np.linspace(0, T_END, 301)
Y = model.solve(np.array([PHI0, W0]), times)
ref = model.bodies_at(times, Y)
print("crank turns:", (Y[-1, 0] - Y[0, 0]) / (2 * math.pi), " min/max omega", Y[:, 1].min(), Y[:, 1].max())

def scene(piston_joint="prismatic", order=None, jorder=None, with_vel=True):
    x0 = {k: v[0] for k, v in ref.items()}
    sc, s_ = math.cos(PHI0), math.sin(PHI0)
    bs = [
        {"name": "crank", "mass": mc, "inertia": Ic, "points": bar(r),
         "position": [float(x0["crank"][0]), float(x0["crank"][1])], "angle": PHI0,
         **({"angular_velocity": W0} if with_vel else {})},
        {"name": "rod", "mass": mr, "inertia": Ir,
         "points": {"A": [-cA[0], -cA[1]], "B": [l - cA[0], -cA[1]]},
         "position": [float(x0["rod"][0]), float(x0["rod"][1])], "angle": float(x0["rod"][2])},
        {"name": "piston", "mass": mp, "inertia": 0.0,
         "position": [float(x0["piston"][0]), e]},
    ]
    if with_vel:
        v0 = model.velocities(Y[0])
        for b in bs:
            vx, vy, w = v0[b["name"]]
            b["velocity"] = [vx, vy]
            if b["inertia"] > 0:
                b["angular_velocity"] = w
    js = [
        {"name": "main", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0.0, 0.0], "O"]},
        {"name": "crankpin", "type": "revolute", "bodies": ["crank", "rod"], "points": ["A", "A"]},
        {"name": "wrist", "type": "revolute", "bodies": ["rod", "piston"], "points": ["B", [0.0, 0.0]]},
        {"name": "cylinder", "type": piston_joint, "bodies": ["ground", "piston"],
         "points": [[0.0, e], [0.0, 0.0]], "axis": [1.0, 0.0]},
    ]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "offset_slider_crank", "dimension": 2, "gravity": [0.0, -9.81], "bodies": bs,
            "joints": js, "outputs": ["energy"],
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    skip = ("piston",)
    trial("slidercrank_prismatic", scene("prismatic"), ref, skip=skip)
    trial("slidercrank_slot", scene("slot"), ref, skip=skip)
    trial("slidercrank_slot_shuffled", scene("slot", order=[2, 0, 1], jorder=[3, 1, 0, 2]), ref, forms=(None,), skip=skip)
    trial("slidercrank_prismatic_reversed", scene("prismatic", order=[2, 1, 0], jorder=[3, 2, 1, 0]), ref, forms=(None,), skip=skip)
