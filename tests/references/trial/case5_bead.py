"""Case 5: bead-in-slot variants. Reference: bar angle th and the bead's coordinate s along the
slot (signed), bead at pivot + R(th) (s, h): smooth through the pivot."""
import math, sys
import numpy as np, sympy as sp
from ref import *

th, s = sp.symbols("th s")

def model(mb=1.0, Lb=1.0, cb=0.5, mk=0.5, h=0.0, k=20.0, anchor=(0.0, 0.0), l0=0.0):
    """bar of length Lb, mass mb, centre at cb from the pivot along the slot direction; slot line
    at offset h; spring between bar point `anchor` (pivot frame) and the bead."""
    R = sp.Matrix([[sp.cos(th), -sp.sin(th)], [sp.sin(th), sp.cos(th)]])
    bead = R * sp.Matrix([s, h])
    cen = R * sp.Matrix([cb, 0])
    dx, dy = s - anchor[0], h - anchor[1]
    V = sp.Rational(1, 2) * k * (sp.sqrt(dx**2 + dy**2) - l0)**2 if l0 else sp.Rational(1, 2) * k * (dx**2 + dy**2)
    bodies = [("bar", mb, mb * Lb**2 / 12, cen[0], cen[1], th), ("bead", mk, 0.0, bead[0], bead[1], sp.Float(0))]
    return Planar([th, s], bodies, v_extra=V)

def scene(ref, mb=1.0, Lb=1.0, cb=0.5, mk=0.5, h=0.0, k=20.0, anchor=(0.0, 0.0), l0=0.0, t_end=3.0,
          rtol=1e-8, atol=1e-10, th0=0.0, bead_angle=None):
    x, y, a = ref["bar"][0]
    bx, by, _ = ref["bead"][0]
    bar_pts = {"P": [-cb, 0.0], "S": [-cb, h], "Q": [anchor[0] - cb, anchor[1]]}
    bd = {"name": "bead", "mass": mk, "inertia": 0.0, "position": [float(bx), float(by)]}
    sc = {"name": "bead_variant", "gravity": [0.0, -9.81],
          "bodies": [{"name": "bar", "mass": mb, "inertia": mb * Lb**2 / 12, "points": bar_pts,
                      "position": [float(x), float(y)], "angle": float(a)}, bd],
          "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "P"]},
                     {"name": "slot", "type": "slot", "bodies": ["bar", "bead"], "points": ["S", [0.0, 0.0]], "axis": [1.0, 0.0]}],
          "springs": [{"name": "spring", "bodies": ["bar", "bead"], "points": ["Q", [0.0, 0.0]], "stiffness": k,
                       "rest_length": l0}],
          "outputs": ["energy"],
          "solve": {"t_end": t_end, "output_step": 0.01, "rtol": rtol, "atol": atol}}
    return sc

CASES = {
    # name: (model kwargs, initial (th, s, thd, sd), t_end)
    "bead_at_pivot": (dict(), (0.0, 0.0, 0.0, 0.0), 3.0),
    "bead_at_pivot_10s": (dict(), (0.0, 0.0, 0.0, 0.0), 10.0),
    "bead_through_pivot_10s": (dict(), (0.0, 0.6, 0.0, 0.0), 10.0),
    "bead_rest_length_offcentre_pin": (dict(Lb=1.5, cb=0.25, k=30.0, anchor=(1.0, 0.0), l0=0.9), (0.0, 0.6, 0.0, 0.0), 3.0),
    "bead_rest_length_offcentre_pin_10s": (dict(Lb=1.5, cb=0.25, k=30.0, anchor=(1.0, 0.0), l0=0.9), (0.0, 0.6, 0.0, 0.0), 10.0),
    "bead_offset_slot": (dict(h=0.1, anchor=(0.0, 0.1)), (0.0, 0.6, 0.0, 0.0), 3.0),
    "bead_offset_slot_10s": (dict(h=0.1, anchor=(0.0, 0.1)), (0.0, 0.6, 0.0, 0.0), 10.0),
    "bead_offset_slot_below": (dict(h=-0.05, anchor=(0.0, -0.05), k=40.0), (0.3, -0.4, 0.0, 0.0), 10.0),
    "bead_no_spring_at_pivot": (dict(k=0.0), (0.0, 0.0, 0.0, 0.0), 1.0),
    "bead_moving_through_pivot": (dict(k=5.0), (-0.5, -0.3, 1.0, 2.0), 10.0),
}

def build(name):
    kw, y0, t_end = CASES[name]
    m = model(**kw)
    times = np.round(np.arange(0, t_end + 1e-9, 0.01), 10)
    Y = m.solve(np.array(y0, dtype=float), times)
    ref = m.bodies_at(times, Y)
    sc = scene(ref, t_end=t_end, **kw)
    v0 = m.velocities(Y[0])
    sc["bodies"][0]["velocity"] = v0["bar"][:2]; sc["bodies"][0]["angular_velocity"] = v0["bar"][2]
    sc["bodies"][1]["velocity"] = v0["bead"][:2]
    return sc, ref, Y

if __name__ == "__main__":
    names = sys.argv[1:] or list(CASES)
    for n in names:
        sc, ref, Y = build(n)
        print(f"-- {n}: s range [{Y[:,1].min():.3f}, {Y[:,1].max():.3f}], sign changes of s: {np.sum(np.diff(np.sign(Y[:,1]))!=0)}")
        trial(n, sc, ref, skip=("bead",))
