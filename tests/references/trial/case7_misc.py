"""Case 7: what a demanding user writes next.
(a) trapeze: a bar hung from the ground by two massless links (distance joints), a point mass
    welded to the bar off its centre, a spring-damper from the ground to the bar's end.
(b) pendulum on a cart whose motion is prescribed (prismatic joint + displacement driver), with a
    spring-damper between the cart and the bob end."""
import math, sys
import numpy as np, sympy as sp
from ref import *

T_END = 3.0
times = np.linspace(0, T_END, 301)

# (a) trapeze
GL, GR, Lk, Lb = (-0.4, 0.0), (0.4, 0.0), 1.0, 0.5
mb, mp = 1.2, 0.4
pm_local = (0.15, 0.05)             # welded point mass, bar frame rel. centre
ks, cs, l0s = 15.0, 0.8, 0.5         # spring-damper: ground (1.0, -0.6) to the bar's right end
GS = (1.0, -0.6)
phi = sp.symbols("phi")
B = sp.Matrix([GL[0] + Lk * sp.cos(phi), GL[1] + Lk * sp.sin(phi)])
Dp = sp.Matrix(GR)
BD = Dp - B; s = sp.sqrt(BD.dot(BD)); u = BD / s
a = (Lb**2 - Lk**2 + s**2) / (2 * s); h = sp.sqrt(Lb**2 - a**2)
C = B + a * u - h * sp.Matrix([-u[1], u[0]])   # the bar's right end (below the line B->D)
thb = sp.atan2(C[1] - B[1], C[0] - B[0])
cen = (B + C) / 2
Rb = sp.Matrix([[sp.cos(thb), -sp.sin(thb)], [sp.sin(thb), sp.cos(thb)]])
P = cen + Rb * sp.Matrix(pm_local)
qd0 = sp.Symbol("qd0")
Ls = sp.sqrt((C[0] - GS[0])**2 + (C[1] - GS[1])**2)
Lsd = sp.diff(Ls, phi) * qd0
trap = Planar([phi], [("bar", mb, mb * Lb**2 / 12, cen[0], cen[1], thb), ("pm", mp, 0.0, P[0], P[1], thb)],
              v_extra=sp.Rational(1, 2) * ks * (Ls - l0s)**2, dissipation=sp.Rational(1, 2) * cs * Lsd**2)
PHI0 = math.radians(-60.0)
Yt = trap.solve(np.array([PHI0, 0.0]), times)
ref_trap = trap.bodies_at(times, Yt)

def trap_scene(order=None, jorder=None, attach="weld"):
    x, y, th = ref_trap["bar"][0]; px, py, _ = ref_trap["pm"][0]
    bs = [{"name": "bar", "mass": mb, "inertia": mb * Lb**2 / 12, "points": {"L": [-Lb / 2, 0], "R": [Lb / 2, 0], "M": list(pm_local)},
           "position": [float(x), float(y)], "angle": float(th)},
          {"name": "pm", "mass": mp, "inertia": 0.0, "position": [float(px), float(py)], "angle": float(th)}]
    js = [{"name": "left", "type": "distance", "bodies": ["ground", "bar"], "points": [list(GL), "L"], "length": Lk},
          {"name": "right", "type": "distance", "bodies": ["ground", "bar"], "points": [list(GR), "R"], "length": Lk},
          {"name": "glue", "type": attach, "bodies": ["bar", "pm"], "points": ["M", [0, 0]]}]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "trapeze", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "springs": [{"name": "sd", "bodies": ["ground", "bar"], "points": [list(GS), "R"], "stiffness": ks,
                         "rest_length": l0s, "damping": cs}],
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

# (b) driven cart pendulum
t = sp.Symbol("t")
A0, Wc = 0.2, 3.0
xc = A0 * sp.sin(Wc * t)
Lp, mpend, mcart = 0.8, 1.0, 2.0
kb, cb = 10.0, 0.5
th = sp.symbols("th")
tip = sp.Matrix([xc + Lp * sp.cos(th), Lp * sp.sin(th)])
cart_anchor = sp.Matrix([xc + 0.3, 0.2])  # cart point (0.3, 0.2) rel. cart centre (cart at y = 0)
dvec = tip - cart_anchor; Lsp = sp.sqrt(dvec.dot(dvec))
Lspd = sp.diff(Lsp, th) * qd0 + sp.diff(Lsp, t)
cartp = Planar([th], [("cart", mcart, 0.1, xc, sp.Float(0), sp.Float(0)),
                      ("pend", mpend, mpend * Lp**2 / 12, xc + Lp / 2 * sp.cos(th), Lp / 2 * sp.sin(th), th)],
               v_extra=sp.Rational(1, 2) * kb * (Lsp - 0.5)**2, dissipation=sp.Rational(1, 2) * cb * Lspd**2)
TH0 = -math.pi / 2 + 0.3
Yc = cartp.solve(np.array([TH0, 0.0]), times)
ref_cart = cartp.bodies_at(times, Yc)

def cart_scene(order=None, jorder=None):
    v0 = cartp.velocities(Yc[0], 0.0)
    x, y, a_ = ref_cart["pend"][0]
    bs = [{"name": "cart", "mass": mcart, "inertia": 0.1, "points": {"H": [0, 0], "S": [0.3, 0.2]},
           "position": [0.0, 0.0], "velocity": [A0 * Wc, 0.0]},
          {"name": "pend", "mass": mpend, "inertia": mpend * Lp**2 / 12, "points": bar(Lp),
           "position": [float(x), float(y)], "angle": float(a_), "velocity": v0["pend"][:2], "angular_velocity": v0["pend"][2]}]
    js = [{"name": "rail", "type": "prismatic", "bodies": ["ground", "cart"], "points": [[0, 0], "H"], "axis": [1, 0]},
          {"name": "hinge", "type": "revolute", "bodies": ["cart", "pend"], "points": ["H", "O"]}]
    if order: bs = [bs[i] for i in order]
    if jorder: js = [js[i] for i in jorder]
    return {"name": "driven_cart_pendulum", "gravity": [0, -9.81], "bodies": bs, "joints": js,
            "drivers": [{"name": "shaker", "joint": "rail", "displacement": f"{A0}*sin({Wc}*t)"}],
            "springs": [{"name": "sd", "bodies": ["cart", "pend"], "points": ["S", "A"], "stiffness": kb,
                         "rest_length": 0.5, "damping": cb}],
            "solve": {"t_end": T_END, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10}}

if __name__ == "__main__":
    trial("trapeze", trap_scene(), ref_trap, skip=("pm",))
    trial("trapeze_pinned_pm", trap_scene(attach="revolute"), ref_trap, skip=("pm",))
    trial("trapeze_pinned_pm_reversed", trap_scene([1, 0], [2, 1, 0], attach="revolute"), ref_trap, forms=(None,), skip=("pm",))
    trial("driven_cart", cart_scene(), ref_cart)
    trial("driven_cart_reversed", cart_scene([1, 0], [1, 0]), ref_cart, forms=(None,))
