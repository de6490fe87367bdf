"""Independent references for the new-user trial (issue 34): minimal-coordinate Lagrange models.

Nothing here uses bondmech. A planar model is given by its generalised coordinates q and, for
every body, its centre (x, y) and angle th as sympy expressions in q, its mass and central
inertia, and an extra potential (springs). Lagrange's equations

    M(q) q'' = -dV/dq - sum_b J_b^T D_b (dJ_b/dt) q'

(J_b = d(x, y, th)/dq, D_b = diag(m, m, I)) are derived by sympy and integrated by scipy's
solve_ivp (DOP853) at rtol = atol = 1e-12 unless told otherwise.
"""
import json
import math
import os
import subprocess
import sys

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

BIN = os.environ.get("BONDMECH", "/tmp/bondmech-main")
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.environ.get("TRIAL_OUT", "/tmp/trial_out")
os.makedirs(OUT, exist_ok=True)


class Planar:
    def __init__(self, q, bodies, g=9.81, v_extra=0, dissipation=None, force=None):
        """bodies: list of (name, m, I, x, y, th); dissipation: Rayleigh function R(q, qd) expr,
        force: generalised force expr vector (function of q, qd, t)."""
        self.q = list(q)
        n = len(self.q)
        self.qd = sp.symbols(f"qd0:{n}")
        self.t = sp.Symbol("t")
        qd = sp.Matrix(self.qd)
        M = sp.zeros(n, n)
        bias = sp.zeros(n, 1)
        V = v_extra
        for (_, m, I, x, y, th) in bodies:
            p = sp.Matrix([x, y, th])
            J = p.jacobian(self.q)
            D = sp.diag(m, m, I)
            M += J.T * D * J
            v = J * qd + sp.diff(p, self.t)  # explicit time (prescribed motion)
            Jdot_qd = v.jacobian(self.q) * qd + sp.diff(v, self.t)
            bias += J.T * D * Jdot_qd
            V += m * g * y
        Q = -sp.Matrix([V]).jacobian(self.q).T - bias
        if dissipation is not None:
            Q += -sp.Matrix([dissipation]).jacobian(list(self.qd)).T
        if force is not None:
            Q += sp.Matrix(force)
        args = [self.t] + self.q + list(self.qd)
        self.fM = sp.lambdify(args, M, cse=True, modules="numpy")
        self.fQ = sp.lambdify(args, Q, cse=True, modules="numpy")
        self.fpos = [
            (name, sp.lambdify(self.q + [self.t], [x, y, th], cse=True, modules="numpy"))
            for (name, m, I, x, y, th) in bodies
        ]
        self.fvel = [
            (name, sp.lambdify(self.q + list(self.qd) + [self.t], sp.Matrix([x, y, th]).jacobian(self.q) * qd + sp.diff(sp.Matrix([x, y, th]), self.t), cse=True, modules="numpy"))
            for (name, m, I, x, y, th) in bodies
        ]
        ke = sp.Rational(1, 2) * (qd.T * M * qd)[0]
        self.fE = sp.lambdify(args, ke + V, cse=True, modules="numpy")
        self.n = n

    def rhs(self, t, y):
        n = self.n
        a = [t] + list(y)
        M = np.array(self.fM(*a), dtype=float)
        Q = np.array(self.fQ(*a), dtype=float).reshape(n)
        return np.concatenate([y[n:], np.linalg.solve(M, Q)])

    def solve(self, y0, times, rtol=1e-12, atol=1e-12):
        sol = solve_ivp(self.rhs, (times[0], times[-1]), y0, method="DOP853", t_eval=times,
                        rtol=rtol, atol=atol)
        assert sol.success, sol.message
        return sol.y.T

    def bodies_at(self, times, Y):
        """{name: array (rows, 3) of x, y, th}"""
        n = self.n
        out = {}
        for name, f in self.fpos:
            out[name] = np.array([f(*(list(Y[i, :n]) + [times[i]])) for i in range(len(times))], dtype=float)
        return out

    def velocities(self, y, t=0.0):
        """{name: [vx, vy, omega]} at state y."""
        return {name: [float(v) for v in np.array(f(*y, t), dtype=float).reshape(3)] for name, f in self.fvel}

    def energy(self, times, Y):
        return np.array([self.fE(times[i], *Y[i]) for i in range(len(times))])


def bar(L):
    return {"O": [-L / 2, 0.0], "A": [L / 2, 0.0]}


def run(scene, tag, formulation=None, extra=()):
    path = os.path.join(OUT, f"{tag}.json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    csv = os.path.join(OUT, f"{tag}.{formulation or 'default'}.csv")
    summ = os.path.join(OUT, f"{tag}.{formulation or 'default'}.summary.json")
    cmd = [BIN, "run", path, "--out", csv, "--summary", summ] + list(extra)
    if formulation:
        cmd += ["--formulation", formulation]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    res = {"rc": p.returncode, "stderr": p.stderr.strip(), "cmd": " ".join(cmd)}
    try:
        res["summary"] = json.load(open(summ))
    except Exception:
        res["summary"] = None
    try:
        import csv as csvmod
        rows = list(csvmod.reader(open(csv)))
        res["header"] = rows[0]
        res["data"] = np.array([[float(x) for x in r] for r in rows[1:]])
    except Exception:
        res["data"] = None
    return res


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def compare(res, ref, angle_bodies=None, skip=()):
    """Max error of body x, y (m) and angle (rad) against ref {name: (rows, 3)}; the rows
    compared are those the run wrote (the ref's rows must be at the same times)."""
    d = res["data"]
    if d is None or len(d) == 0:
        return float("nan"), float("nan")
    h = res["header"]
    rows = len(d)
    ep, ea = 0.0, 0.0
    for name, arr in ref.items():
        ix, iy, ia = h.index(f"{name}.x"), h.index(f"{name}.y"), h.index(f"{name}.angle")
        ep = max(ep, np.max(np.abs(d[:, ix] - arr[:rows, 0])), np.max(np.abs(d[:, iy] - arr[:rows, 1])))
        if name not in skip:
            ea = max(ea, np.max(np.abs(wrap(d[:, ia] - arr[:rows, 2]))))
    return ep, ea


def report(tag, res, ref, skip=(), t_end=None):
    s = res["summary"] or {}
    ep, ea = compare(res, ref, skip=skip)
    warns = s.get("warnings", [])
    d = res["data"]
    t_last = d[-1, 0] if d is not None and len(d) else None
    line = (f"{tag:38s} rc={res['rc']} form={s.get('formulation')} steps={s.get('steps')} "
            f"t_reached={s.get('t_reached')} pos_err={ep:.2e} ang_err={ea:.2e} "
            f"drift={s.get('energy_drift')} resel={s.get('index1_reselections')} "
            f"sing={len(s.get('singular_passages', []) or [])} cerr={s.get('max_constraint_error')}")
    print(line)
    for w in warns:
        print("     warning:", w[:300])
    if res["rc"] != 0:
        print("     stderr:", res["stderr"][:600])
    return ep, ea


def trial(tag, scene, ref, forms=(None, "ggl", "partitioned"), skip=()):
    out = {}
    for f in forms:
        res = run(scene, tag, f)
        out[f] = report(f"{tag}[{f or 'default'}]", res, ref, skip=skip)
        out[f] = out[f] + (res,)
    return out


class PlanarConstrained(Planar):
    """As Planar with holonomic constraints c(q) = 0 kept by multipliers (index 1):
    [M C^T; C 0] [q''; lam] = [Q; -d/dt(C) q'], for references that must pass points where no
    single minimal coordinate is regular (a four-bar's toggles)."""

    def __init__(self, q, bodies, constraints, **kw):
        super().__init__(q, bodies, **kw)
        c = sp.Matrix(constraints)
        Cq = c.jacobian(self.q)
        qd = sp.Matrix(self.qd)
        gam = (Cq * qd).jacobian(self.q) * qd
        args = [self.t] + self.q + list(self.qd)
        self.fC = sp.lambdify(args, Cq, cse=True, modules="numpy")
        self.fg = sp.lambdify(args, gam, cse=True, modules="numpy")
        self.fc = sp.lambdify(self.q, c, cse=True, modules="numpy")
        self.m = len(constraints)

    def rhs(self, t, y):
        n, m = self.n, self.m
        a = [t] + list(y)
        M = np.array(self.fM(*a), dtype=float)
        Q = np.array(self.fQ(*a), dtype=float).reshape(n)
        C = np.array(self.fC(*a), dtype=float).reshape(m, n)
        g = np.array(self.fg(*a), dtype=float).reshape(m)
        K = np.block([[M, C.T], [C, np.zeros((m, m))]])
        x = np.linalg.solve(K, np.concatenate([Q, -g]))
        return np.concatenate([y[n:], x[:n]])

    def solve(self, y0, times, rtol=1e-12, atol=1e-12):
        Y = super().solve(y0, times, rtol, atol)
        viol = max(np.max(np.abs(np.array(self.fc(*Y[i, :self.n]), dtype=float))) for i in range(len(Y)))
        print(f"   reference constraint drift {viol:.1e}")
        return Y


class PinModel:
    """Planar bodies joined by pins in absolute coordinates z = (x_i, y_i, th_i), Newton-Euler
    with multipliers: g = r_a + R(th_a) s_a - r_b - R(th_b) s_b = 0 per pin (s_a global when a is
    the ground), [M C^T; C 0] [z''; lam] = [F; sum sign th'^2 R s]. Fast (numpy only)."""

    def __init__(self, bodies, pins, g=9.81):
        self.bodies, self.pins, self.g = bodies, pins, g

    def acc(self, z, zd):
        n, m = 3 * len(self.bodies), 2 * len(self.pins)
        K = np.zeros((n + m, n + m)); rhs = np.zeros(n + m)
        for i, (mass, inertia) in enumerate(self.bodies):
            K[3 * i, 3 * i] = K[3 * i + 1, 3 * i + 1] = mass
            K[3 * i + 2, 3 * i + 2] = inertia if inertia > 0 else 1.0
            rhs[3 * i + 1] = -mass * self.g
        for p, (a, sa, b, sb) in enumerate(self.pins):
            row = n + 2 * p
            for body, s, sign in ([(a, sa, 1.0)] if a is not None else []) + [(b, sb, -1.0)]:
                th = z[3 * body + 2]; c, sn = math.cos(th), math.sin(th)
                rs = (c * s[0] - sn * s[1], sn * s[0] + c * s[1])
                perp = (-rs[1], rs[0])
                for d in range(2):
                    K[row + d, 3 * body + d] = K[3 * body + d, row + d] = sign
                    K[row + d, 3 * body + 2] = K[3 * body + 2, row + d] = sign * perp[d]
                    rhs[row + d] += sign * zd[3 * body + 2] ** 2 * rs[d]
        return np.linalg.solve(K, rhs)[:n]

    def solve(self, z0, times, rtol=1e-12, atol=1e-12):
        n = len(z0)
        f = lambda t, y: np.concatenate([y[n:], self.acc(y[:n], y[n:])])
        s = solve_ivp(f, (times[0], times[-1]), np.concatenate([z0, np.zeros(n)]), method="DOP853",
                      t_eval=times, rtol=rtol, atol=atol)
        assert s.success, s.message
        return s.y.T[:, :n]


class FiveBar:
    """A five-bar: cranks c1 (length L1, from the origin) and c4 (L4, from (d, 0)), couplers k2
    (L2, from c1's tip) and k3 (L3, from c4's tip) pinned together; uniform bars of masses m,
    inertias m L^2 / 12. The model is the four link angles with the loop closure kept by
    multipliers (`PlanarConstrained`), regular where the couplers line up."""

    def __init__(self, d, lengths, masses):
        self.d, self.L, self.m = d, list(lengths), list(masses)
        L1, L2, L3, L4 = self.L
        t = sp.symbols("t1:5")
        u = lambda a: sp.Matrix([sp.cos(a), sp.sin(a)])
        B = L1 * u(t[0]); Dp = sp.Matrix([d, 0]) + L4 * u(t[3])
        C2 = B + L2 * u(t[1]); C3 = Dp + L3 * u(t[2])
        m = self.m
        self.bodies = [("c1", m[0], m[0] * L1**2 / 12, *(L1 / 2 * u(t[0])), t[0]),
                       ("k2", m[1], m[1] * L2**2 / 12, *(B + L2 / 2 * u(t[1])), t[1]),
                       ("k3", m[2], m[2] * L3**2 / 12, *(Dp + L3 / 2 * u(t[2])), t[2]),
                       ("c4", m[3], m[3] * L4**2 / 12, *(sp.Matrix([d, 0]) + L4 / 2 * u(t[3])), t[3])]
        self.model = PlanarConstrained(list(t), self.bodies, list(C2 - C3))

    def start(self, q1, q4, up=True):
        """The four angles with the cranks at q1, q4 (the couplers' joint above their line when
        `up`): the two circles' intersection in closed form."""
        L1, L2, L3, L4 = self.L
        b = np.array([L1 * math.cos(q1), L1 * math.sin(q1)])
        dd = np.array([self.d + L4 * math.cos(q4), L4 * math.sin(q4)])
        s = np.linalg.norm(dd - b); uu = (dd - b) / s
        a = (L2**2 - L3**2 + s**2) / (2 * s); h = math.sqrt(L2**2 - a**2)
        c = b + a * uu + (1 if up else -1) * h * np.array([-uu[1], uu[0]])
        return [q1, math.atan2(*(c - b)[::-1]), math.atan2(*(c - dd)[::-1]), q4]

    def scene(self, name, first, solve):
        """The scene with the bodies at `first` ({name: (x, y, angle)}, a reference row)."""
        bs = []
        for (bn, mm, I, *_), L in zip(self.bodies, self.L):
            x, y, a = first[bn]
            bs.append({"name": bn, "mass": mm, "inertia": I, "points": bar(L),
                       "position": [float(x), float(y)], "angle": float(a)})
        js = [{"name": "A", "type": "revolute", "bodies": ["ground", "c1"], "points": [[0, 0], "O"]},
              {"name": "B", "type": "revolute", "bodies": ["c1", "k2"], "points": ["A", "O"]},
              {"name": "C", "type": "revolute", "bodies": ["k2", "k3"], "points": ["A", "A"]},
              {"name": "D", "type": "revolute", "bodies": ["k3", "c4"], "points": ["O", "A"]},
              {"name": "E", "type": "revolute", "bodies": ["ground", "c4"], "points": [[self.d, 0], "O"]}]
        return {"name": name, "dimension": 2, "gravity": [0, -9.81], "bodies": bs, "joints": js,
                "solve": solve}
