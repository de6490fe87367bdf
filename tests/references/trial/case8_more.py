"""Case 8: (a) non-Grashof triple-rocker four-bar swinging through its toggle positions (the
crank angle has turning points: a partition with the crank independent fails there);
(b) planar over-constrained parallelogram: three equal cranks on one coupler (redundant joints),
swinging; (c) two rigid bodies welded into one compound pendulum."""
import math, sys
import numpy as np, sympy as sp
from ref import *

T_END = 3.0
times = np.linspace(0, T_END, 301)

# (a) triple rocker: ground 1.0, crank 0.8, coupler 0.6, rocker 0.9 (l+s = 1.0+0.6=1.6 > 0.8+0.9=1.7? no)
# non-Grashof: s + l > p + q: s=0.3, l=1.0, p=0.8, q=0.9?  0.3+1.0 = 1.3 < 1.7 Grashof. Use
# ground 1.0, crank 0.9, coupler 0.35, rocker 0.8: s + l = 0.35 + 1.0 = 1.35 < 1.7 still Grashof.
# ground 0.5, crank 1.0, coupler 0.9, rocker 0.8: s+l = 0.5+1.0=1.5 < 1.7 Grashof (ground shortest:
# double crank). Take ground 1.2, crank 0.5, coupler 0.5, rocker 1.1: s+l = 0.5+1.2=1.7 > 1.6. non-Grashof.
d, L1, L2, L3 = 1.2, 0.5, 0.5, 1.1
m1, m2, m3 = 1.0, 0.6, 1.2
ps = sp.symbols("ps")       # the rocker angle at D is not monotone either; use the coupler-rocker
# Minimal coordinate valid through the crank's toggles: the rocker angle th3 at D=(d,0) has
# toggles too. Use instead the angle of the diagonal? Simplest: parametrise by the crank angle th1
# and switch the branch sign at its toggles -- as in the change-point case, write C smoothly in a
# coordinate that is monotone. Here use the angle q of the rocker and solve the crank from the
# circles around A and C: B = A + L1 u(alpha), with h's sign flipping at the crank's toggles...
# The toggles of the crank are where the coupler and the rocker are aligned; the rocker angle is
# regular there. Toggles of the rocker (crank and coupler aligned) are where the crank angle is
# regular. A single minimal coordinate regular at both: neither. We keep the motion inside a range
# where only crank toggles occur (rocker swings without reaching its limits).
# coordinates: crank angle t1 and rocker angle t3, one closure |C - B| = L2 kept by a multiplier
t1, t3 = sp.symbols("t1 t3")
B = sp.Matrix([L1 * sp.cos(t1), L1 * sp.sin(t1)])
C = sp.Matrix([d + L3 * sp.cos(t3), L3 * sp.sin(t3)])
th2 = sp.atan2(C[1] - B[1], C[0] - B[0])
tr_b = [("crank", m1, m1 * L1**2 / 12, B[0] / 2, B[1] / 2, t1),
        ("coupler", m2, m2 * L2**2 / 12, (B[0] + C[0]) / 2, (B[1] + C[1]) / 2, th2),
        ("rocker", m3, m3 * L3**2 / 12, d + L3 / 2 * sp.cos(t3), L3 / 2 * sp.sin(t3), t3)]
tri = PlanarConstrained([t1, t3], tr_b, [((C - B).dot(C - B) - L2**2) / 2])
# start: rocker at 150 deg, crank on the branch above the line A-C
q0 = math.radians(150.0)
Cn = np.array([d + L3 * math.cos(q0), L3 * math.sin(q0)]); sn = np.linalg.norm(Cn); un = Cn / sn
an = (L1**2 - L2**2 + sn**2) / (2 * sn); hn = math.sqrt(L1**2 - an**2)
Bn = an * un + hn * np.array([-un[1], un[0]])
Yr = tri.solve(np.array([math.atan2(Bn[1], Bn[0]), q0, 0.0, 0.0]), times)
print("triple rocker: crank range", np.degrees(Yr[:, 0].min()), np.degrees(Yr[:, 0].max()),
      "rocker range", np.degrees(Yr[:, 1].min()), np.degrees(Yr[:, 1].max()))
ref_tri = tri.bodies_at(times, Yr)

def fourbar_scene(ref, names_L_m, ground_pts, t_end=T_END, extra_joints=()):
    bs = []
    for name, L, m in names_L_m:
        x, y, a_ = ref[name][0]
        bs.append({"name": name, "mass": m, "inertia": m * L**2 / 12, "points": bar(L),
                   "position": [float(x), float(y)], "angle": float(a_)})
    return bs

def tri_scene():
    bs = fourbar_scene(ref_tri, [("crank", L1, m1), ("coupler", L2, m2), ("rocker", L3, m3)], None)
    js = [{"name": "A", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], "O"]},
          {"name": "B", "type": "revolute", "bodies": ["crank", "coupler"], "points": ["A", "O"]},
          {"name": "C", "type": "revolute", "bodies": ["coupler", "rocker"], "points": ["A", "A"]},
          {"name": "D", "type": "revolute", "bodies": ["ground", "rocker"], "points": [[d, 0], "O"]}]
    return {"name": "triple_rocker", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

# (b) three equal cranks (length Lc, pitch p) on one coupler: parallelogram branch, coupler translates
Lc, pitch, mcr, mco = 0.6, 0.5, 0.7, 1.5
phi = sp.symbols("phi")
cranks = [(f"k{i}", mcr, mcr * Lc**2 / 12, i * pitch + Lc / 2 * sp.cos(phi), Lc / 2 * sp.sin(phi), phi) for i in range(3)]
coupler = ("cp", mco, mco * (2 * pitch)**2 / 12, pitch + Lc * sp.cos(phi), Lc * sp.sin(phi), sp.Float(0))
par = Planar([phi], cranks + [coupler])
Yp = par.solve(np.array([math.radians(-30.0), 0.0]), times)
ref_par = par.bodies_at(times, Yp)
def par_scene():
    bs = []
    for i in range(3):
        x, y, a_ = ref_par[f"k{i}"][0]
        bs.append({"name": f"k{i}", "mass": mcr, "inertia": mcr * Lc**2 / 12, "points": bar(Lc),
                   "position": [float(x), float(y)], "angle": float(a_)})
    x, y, _ = ref_par["cp"][0]
    bs.append({"name": "cp", "mass": mco, "inertia": mco * (2 * pitch)**2 / 12,
               "points": {"P0": [-pitch, 0], "P1": [0, 0], "P2": [pitch, 0]}, "position": [float(x), float(y)]})
    js = [{"name": f"g{i}", "type": "revolute", "bodies": ["ground", f"k{i}"], "points": [[i * pitch, 0], "O"]} for i in range(3)]
    js += [{"name": f"c{i}", "type": "revolute", "bodies": [f"k{i}", "cp"], "points": ["A", f"P{i}"]} for i in range(3)]
    return {"name": "triple_crank_parallelogram", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

# (c) two welded bodies = one compound pendulum: a bar (1 m, 1 kg) pinned at its end, a disc
# (0.3 kg, J 0.002) welded at the bar's far end at an angle
th = sp.symbols("th")
wb = [("rod", 1.0, 1 / 12, 0.5 * sp.cos(th), 0.5 * sp.sin(th), th),
      ("disc", 0.3, 0.002, 1.0 * sp.cos(th) - 0.1 * sp.sin(th), 1.0 * sp.sin(th) + 0.1 * sp.cos(th), th + 0.7)]
wm = Planar([th], wb)
Yw = wm.solve(np.array([0.2, 0.0]), times)
ref_w = wm.bodies_at(times, Yw)
def weld_scene():
    x, y, a_ = ref_w["rod"][0]; dx, dy, da = ref_w["disc"][0]
    # disc centre in rod frame at (0.5, 0.1); weld at the rod's end A=(0.5, 0) and the disc point W
    Wd = np.array([[math.cos(0.7), math.sin(0.7)], [-math.sin(0.7), math.cos(0.7)]]) @ np.array([0.0, -0.1])
    return {"name": "welded_pendulum", "gravity": [0, -9.81],
            "bodies": [{"name": "rod", "mass": 1.0, "inertia": 1 / 12, "points": bar(1.0), "position": [float(x), float(y)], "angle": float(a_)},
                       {"name": "disc", "mass": 0.3, "inertia": 0.002, "points": {"W": list(Wd)}, "position": [float(dx), float(dy)], "angle": float(da)}],
            "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "rod"], "points": [[0, 0], "O"]},
                       {"name": "glue", "type": "weld", "bodies": ["rod", "disc"], "points": ["A", "W"]}],
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    trial("triple_rocker", tri_scene(), ref_tri)
    trial("triple_crank_parallelogram", par_scene(), ref_par)
    trial("welded_pendulum", weld_scene(), ref_w)
