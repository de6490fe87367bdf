"""Scene.sensitivity and Scene.fit: numpy arrays equal to the command line's CSV, a fit from a
DataFrame, and bad paths raising OptionsError naming them."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

import bondmech

PARAM = "bodies[bar2].mass"


def test_sensitivity_is_the_cli_csv(double_pendulum_path, cli):
    s = bondmech.load(double_pendulum_path).sensitivity([PARAM], t_end=0.3)
    name = f"d(bar2.angle)/d({PARAM})"
    assert s["t"].shape == (31,) and s["values"].shape == (31, len(s["columns"]))
    d = s["sensitivities"][name]
    assert d.shape == (31,) and d[0] == 0.0 and abs(d[-1]) > 0.0
    out = cli("sensitivity", str(double_pendulum_path), "--param", PARAM, "--t-end", "0.3").stdout
    rows = list(csv.reader(io.StringIO(out)))
    col = rows[0].index(name)
    assert np.array_equal(d, np.array([float(r[col]) for r in rows[1:]]))


def test_bad_path_raises_options_error_naming_it(double_pendulum_path):
    with pytest.raises(bondmech.OptionsError, match=r"bodies\[bar9\]"):
        bondmech.load(double_pendulum_path).sensitivity(["bodies[bar9].mass"])


def _block(k):
    return {
        "name": "block", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [{"name": "block", "mass": 2.0, "inertia": 0.01, "points": {"c": [0.0, 0.0]},
                    "position": [0.1, 0.0], "angle": 0.0}],
        "joints": [{"name": "rail", "type": "prismatic", "bodies": ["ground", "block"],
                    "points": [[0.0, 0.0], "c"], "axis": [1.0, 0.0]}],
        "springs": [{"name": "s1", "bodies": ["ground", "block"], "points": [[0.0, 0.0], "c"],
                     "stiffness": k, "damping": 1.5, "rest_length": 0.0}],
        "solve": {"t_end": 2.0, "output_step": 0.05, "rtol": 1e-9, "atol": 1e-11},
    }


def test_fit_from_a_dataframe():
    pd = pytest.importorskip("pandas")
    m, k, c, x0 = 2.0, 50.0, 1.5, 0.1
    a = c / (2 * m)
    w = math.sqrt(k / m - a * a)
    t = np.arange(1, 41) * 0.05
    x = x0 * np.exp(-a * t) * (np.cos(w * t) + a / w * np.sin(w * t))
    data = pd.DataFrame({"t": t, "block.x": x})
    r = bondmech.load(_block(1.2 * k)).fit(data, ["springs[s1].stiffness"])
    assert r["converged"] is True
    assert abs(r["parameters"]["springs[s1].stiffness"] - k) < 1e-4 * k
    # the same from a dict of columns
    r2 = bondmech.load(_block(1.2 * k)).fit({"t": list(t), "block.x": list(x)}, ["springs[s1].stiffness"])
    assert r2["parameters"] == r["parameters"]
