"""The double pendulum from Python against an independent model written here: the two bar
angles as minimal coordinates, Lagrange's equations derived by hand, integrated by SciPy's
DOP853 at rtol 1e-12. Nothing of bondmech is used to build the reference but the scene's numbers."""

from __future__ import annotations

import json

import numpy as np
import pytest

import bondmech

scipy_integrate = pytest.importorskip("scipy.integrate")


def lagrange_double_pendulum(scene: dict):
    """Right-hand side of the double pendulum of two bars hinged at their ends.

    θ₁, θ₂: the bars' angles from the x axis; bar 1 pinned at the origin at its end O.
    Centres of mass at a = ℓ/2 along each bar; bar 2 hangs at bar 1's end A (ℓ₁ from O).
    T = ½(m₁a₁² + J₁ + m₂ℓ₁²)θ₁'² + m₂ℓ₁a₂cos(θ₁−θ₂)θ₁'θ₂' + ½(m₂a₂² + J₂)θ₂'²
    V = m₁ g a₁ sin θ₁ + m₂ g (ℓ₁ sin θ₁ + a₂ sin θ₂)
    M(θ)θ'' = [−m₂ℓ₁a₂ sin(θ₁−θ₂)θ₂'² − (m₁a₁ + m₂ℓ₁) g cos θ₁,
               +m₂ℓ₁a₂ sin(θ₁−θ₂)θ₁'² − m₂ a₂ g cos θ₂]
    """
    b1, b2 = scene["bodies"]
    m1, j1, m2, j2 = b1["mass"], b1["inertia"], b2["mass"], b2["inertia"]
    a1 = -b1["points"]["O"][0]  # the pin is at O, a₁ from the centre of mass
    l1 = b1["points"]["A"][0] - b1["points"]["O"][0]
    a2 = -b2["points"]["O"][0]
    g = -scene["gravity"][1]

    def rhs(_t, y):
        th1, th2, w1, w2 = y
        c, s = np.cos(th1 - th2), np.sin(th1 - th2)
        m11 = m1 * a1**2 + j1 + m2 * l1**2
        m12 = m2 * l1 * a2 * c
        m22 = m2 * a2**2 + j2
        f1 = -m2 * l1 * a2 * s * w2**2 - (m1 * a1 + m2 * l1) * g * np.cos(th1)
        f2 = m2 * l1 * a2 * s * w1**2 - m2 * a2 * g * np.cos(th2)
        det = m11 * m22 - m12 * m12
        return [w1, w2, (m22 * f1 - m12 * f2) / det, (m11 * f2 - m12 * f1) / det]

    return rhs, l1


def test_double_pendulum_matches_minimal_coordinate_lagrange(double_pendulum_path):
    raw = json.loads(double_pendulum_path.read_text())
    rhs, l1 = lagrange_double_pendulum(raw)
    t_end = 2.0
    sol = bondmech.load(double_pendulum_path).run(t_end=t_end, rtol=1e-10, atol=1e-12)
    ref = scipy_integrate.solve_ivp(rhs, (0.0, t_end), [0.0, 0.0, 0.0, 0.0], method="DOP853",
                                    t_eval=sol.t, rtol=1e-12, atol=1e-12)
    assert ref.success
    th1, th2, w1, w2 = ref.y
    err_angle = max(np.max(np.abs(sol["bar1.angle"] - th1)), np.max(np.abs(sol["bar2.angle"] - th2)))
    err_omega = max(np.max(np.abs(sol["bar1.omega"] - w1)), np.max(np.abs(sol["bar2.omega"] - w2)))
    # the tip: bar 1's length plus bar 2's end A
    tip_x = l1 * np.cos(th1) + (raw["bodies"][1]["points"]["A"][0] - raw["bodies"][1]["points"]["O"][0]) * np.cos(th2)
    err_tip = np.max(np.abs(sol["bar2.A.x"] - tip_x))
    assert err_angle < 1e-7, err_angle
    assert err_omega < 1e-6, err_omega
    assert err_tip < 1e-7, err_tip
    # the motion is not trivial: the pendulum has swung through more than a radian
    assert np.max(np.abs(th1)) > 1.0
    # a wrong model is told apart: the same reference with bar 2 twice as heavy is far away
    heavy = json.loads(json.dumps(raw))
    heavy["bodies"][1]["mass"] = 2.0
    rhs2, _ = lagrange_double_pendulum(heavy)
    other = scipy_integrate.solve_ivp(rhs2, (0.0, t_end), [0.0] * 4, method="DOP853",
                                      t_eval=sol.t, rtol=1e-12, atol=1e-12)
    assert np.max(np.abs(sol["bar2.angle"] - other.y[1])) > 1e-2


def test_double_pendulum_conserves_energy_and_keeps_the_pins(double_pendulum_path):
    sol = bondmech.load(double_pendulum_path).run(t_end=3.0)
    e = sol["energy"]
    assert np.max(np.abs(e - e[0])) < 1e-5 * 9.81
    assert np.max(sol["constraint_error"]) < 1e-8
