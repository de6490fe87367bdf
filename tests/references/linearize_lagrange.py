"""Reference linear models for tests/linearize.rs, derived by a Lagrangian in sympy (not run
in CI; the closed forms it prints are written into the test).

1. Hanging double pendulum of two uniform bars (m1, L1), (m2, L2), angles phi1, phi2 from the
   downward vertical, pinned at the origin and at bar 1's end: M, K about phi = 0.
2. A uniform bar (m, L) on a pin at its end with a viscous torque -c*omega and an input torque
   u: J phi'' + c phi' + K phi = u about hanging.

Run: python3 tests/references/linearize_lagrange.py
"""
import sympy as sp

t = sp.symbols("t")
m1, m2, L1, L2, g = sp.symbols("m1 m2 L1 L2 g", positive=True)
p1, p2 = sp.Function("phi1")(t), sp.Function("phi2")(t)
# centres of mass (y up; the bars hang along -y at phi = 0)
x1, y1 = L1 / 2 * sp.sin(p1), -L1 / 2 * sp.cos(p1)
x2 = L1 * sp.sin(p1) + L2 / 2 * sp.sin(p2)
y2 = -L1 * sp.cos(p1) - L2 / 2 * sp.cos(p2)
J1, J2 = m1 * L1**2 / 12, m2 * L2**2 / 12
T = (m1 * (x1.diff(t) ** 2 + y1.diff(t) ** 2) + J1 * p1.diff(t) ** 2
     + m2 * (x2.diff(t) ** 2 + y2.diff(t) ** 2) + J2 * p2.diff(t) ** 2) / 2
V = m1 * g * y1 + m2 * g * y2
q = [p1, p2]
qd = [p.diff(t) for p in q]
# M = d²T/dq̇², K = d²V/dq² at phi = 0
at0 = {p1: 0, p2: 0}
M = sp.Matrix(2, 2, lambda i, j: sp.simplify(T.diff(qd[i]).diff(qd[j]).subs(at0)))
K = sp.Matrix(2, 2, lambda i, j: sp.simplify(V.diff(q[i]).diff(q[j]).subs(at0)))
print("double pendulum M =", M)
print("double pendulum K =", K)
# the generalised eigenproblem det(K - w² M) = 0 in closed form
w2 = sp.symbols("w2")
print("det(K - w2 M) =", sp.expand(sp.det(K - w2 * M)))

# 2. damped pendulum with an input torque
m, L, c, u = sp.symbols("m L c u", positive=True)
p = sp.Function("phi")(t)
xb, yb = L / 2 * sp.sin(p), -L / 2 * sp.cos(p)
Tb = (m * (xb.diff(t) ** 2 + yb.diff(t) ** 2) + m * L**2 / 12 * p.diff(t) ** 2) / 2
Vb = m * g * yb
Jb = sp.simplify(Tb.diff(p.diff(t)).diff(p.diff(t)))
Kb = sp.simplify(Vb.diff(p).diff(p).subs(p, 0))
print("pendulum J =", Jb, " K =", Kb, " (J phi'' + c phi' + K phi = u: H(s) = 1/(J s² + c s + K))")
