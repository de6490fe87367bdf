"""Scene and Solution: loading, set, to_dict, the arrays, the summary, pandas, pickling."""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

import bondmech
from conftest import SCENES


def test_run_returns_numpy_arrays_of_the_csv_shape(double_pendulum_path):
    sol = bondmech.load(double_pendulum_path).run(t_end=0.5)
    assert isinstance(sol, bondmech.Solution)
    assert sol.t.dtype == np.float64 and sol.t.ndim == 1
    assert sol.values.dtype == np.float64 and sol.values.shape == (51, len(sol.columns))
    assert sol.t[0] == 0.0 and sol.t[-1] == 0.5 and len(sol) == 51
    # the CSV's columns, in order: six per planar body, the point, energy, constraint error
    assert sol.columns[:6] == ["bar1.x", "bar1.y", "bar1.angle", "bar1.vx", "bar1.vy", "bar1.omega"]
    assert sol.columns[-1] == "constraint_error"
    assert {"bar2.A.x", "bar2.A.y", "energy"} <= set(sol.columns)


def test_getitem_is_a_column_and_unknown_names_raise_keyerror(double_pendulum_path):
    sol = bondmech.load(double_pendulum_path).run(t_end=0.2)
    c = sol.columns.index("bar1.angle")
    assert np.array_equal(sol["bar1.angle"], sol.values[:, c])
    assert np.array_equal(sol["t"], sol.t)
    assert "bar1.angle" in sol and "nope" not in sol
    with pytest.raises(KeyError, match="bar1.angle"):
        sol["nope"]


def test_arrays_are_read_only(double_pendulum_path):
    sol = bondmech.load(double_pendulum_path).run(t_end=0.1)
    with pytest.raises(ValueError):
        sol.values[0, 0] = 1.0
    with pytest.raises(ValueError):
        sol.t[0] = 1.0


def test_summary_is_the_summary_json(double_pendulum_path):
    sol = bondmech.load(double_pendulum_path).run(t_end=0.5)
    s = sol.summary
    for key in ("formulation", "steps", "residual_evals", "jacobian_evals", "error_test_failures",
                "nonlinear_iterations", "cpu_seconds", "max_constraint_error", "energy_drift"):
        assert key in s, key
    assert s["steps"] > 10 and s["completed"] is True and s["t_reached"] == 0.5
    assert s == json.loads(sol.summary_json())
    assert s["max_constraint_error"] < 1e-8


def test_to_pandas_has_the_columns_indexed_by_t(double_pendulum_path):
    pd = pytest.importorskip("pandas")
    sol = bondmech.load(double_pendulum_path).run(t_end=0.2)
    df = sol.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == sol.columns and df.index.name == "t"
    assert np.array_equal(df.index.to_numpy(), sol.t)
    assert np.array_equal(df["bar2.A.y"].to_numpy(), sol["bar2.A.y"])


def test_set_uses_the_cli_paths_and_changes_the_motion(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    light = scene.run(t_end=0.5)
    assert scene.set("bodies[bar2].mass", 2.0) is scene
    assert scene.sets == ["bodies[bar2].mass=2.0"]
    heavy = scene.run(t_end=0.5)
    assert scene.to_dict()["bodies"][1]["mass"] == 2.0
    assert not np.array_equal(light["bar2.A.y"], heavy["bar2.A.y"])
    # numpy values are accepted
    scene.set("gravity", np.array([0.0, -1.62]))
    assert scene.to_dict()["gravity"] == [0.0, -1.62]


def test_to_dict_round_trips_through_load(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path).set("bodies[1].mass", 1.5)
    again = bondmech.load(scene.to_dict())
    a, b = scene.run(t_end=0.3), again.run(t_end=0.3)
    assert np.array_equal(a.values, b.values) and a.columns == b.columns


def test_scene_pickles_with_its_sets(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path).set("bodies[bar2].mass", 3.0)
    clone = pickle.loads(pickle.dumps(scene))
    assert clone.sets == scene.sets and clone.to_dict() == scene.to_dict()
    assert np.array_equal(clone.run(t_end=0.2).values, scene.run(t_end=0.2).values)


def test_run_arguments_override_the_solve_section(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    sol = scene.run(t_end=0.3, formulation="index1", rtol=1e-6, atol=1e-8, reactions=True,
                    linear_solver="dense")
    assert sol.summary["formulation"] == "index1"
    assert sol.summary["linear_solver"] == "dense"
    assert {"pivot.Fx", "pivot.Fy", "knee.Fx", "knee.Fy"} <= set(sol.columns)
    # the scene itself is unchanged
    assert scene.to_dict()["solve"]["rtol"] == 1e-8


def test_compare_is_the_compare_json(double_pendulum_path):
    out = bondmech.compare(bondmech.load(double_pendulum_path), joint_stiffness=1e6, t_end=0.2)
    assert isinstance(out, dict)
    # the scene's formulation on IDA against the twin on CVODE, and the largest differences
    assert out["dae"]["formulation"] != "decoupled" and out["dae"]["solver"] == "IDA"
    assert out["decoupled"]["formulation"] == "decoupled" and out["decoupled"]["solver"] == "CVODE"
    assert {"position", "angle", "velocity"} <= set(out)


def test_graph_gives_dot_and_the_causality_report(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    dot = bondmech.graph(scene)
    assert isinstance(dot, str) and dot.lstrip().startswith("digraph")
    report = bondmech.graph(scene, causality=True)
    # seed 16.7: two integral inertias (the DOF), four in differential causality
    assert report["dof"] == 2 and len(report["differential"]) == 4
    assert bondmech.graph(scene, decoupled=True) != dot


def test_equilibrium_is_the_cli_document_and_a_driven_run_has_driver_columns(tmp_path, cli):
    four_bar = SCENES / "four_bar.json"
    eq = bondmech.load(four_bar).equilibrium()
    assert set(eq) == {"converged", "iterations", "residual", "coordinates", "reactions",
                       "drivers", "stable", "stability", "stiffness_eigenvalues", "cpu_seconds"}
    out = tmp_path / "eq.json"
    cli("equilibrium", str(four_bar), "--json", str(out))
    doc = json.loads(out.read_text())
    # the CPU time is each run's own
    assert eq.pop("cpu_seconds") >= 0 and doc.pop("cpu_seconds") >= 0
    assert eq == doc
    sol = bondmech.load(SCENES / "slider_crank_driven.json").run(t_end=0.1)
    assert "motor.torque" in sol and "motor.power" in sol


def test_linearize_returns_numpy_matrices_and_the_cli_modes(tmp_path, cli):
    # the damped pendulum with an input torque: J θ'' + c θ' + K θ = u about hanging
    m, length, c, g = 1.2, 0.9, 0.25, 9.81
    scene = {
        "gravity": [0.0, -g],
        "inputs": [{"name": "tau", "start": 0.0}],
        "bodies": [{"name": "bar", "mass": m, "inertia": m * length**2 / 12,
                    "points": {"O": [-length / 2, 0.0], "A": [length / 2, 0.0]},
                    "position": [0.0, -length / 2], "angle": -np.pi / 2}],
        "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0.0, 0.0], "O"]}],
        "loads": [{"type": "torque", "body": "bar", "value": f"-{c}*bar.omega + tau"}],
        "solve": {"t_end": 1.0},
    }
    path = tmp_path / "damped.json"
    path.write_text(json.dumps(scene))
    lin = bondmech.load(path).linearize(outputs=["bar.angle"])
    assert lin["states"] == ["bar.angle", "bar.omega"] and lin["inputs"] == ["tau"]
    for key, shape in [("A", (2, 2)), ("B", (2, 1)), ("C", (1, 2)), ("D", (1, 1))]:
        assert isinstance(lin[key], np.ndarray) and lin[key].shape == shape, key
    j, k = m * length**2 / 3, m * g * length / 2
    # A = [[0, 1], [-K/J, -c/J]], B = [0, 1/J] (the hand-derived model)
    assert np.allclose(lin["A"], [[0, 1], [-k / j, -c / j]], rtol=1e-10, atol=1e-12)
    assert np.allclose(lin["B"][:, 0], [0, 1 / j], rtol=1e-10, atol=1e-12)
    out = tmp_path / "lin.json"
    cli("linearize", str(path), "--output", "bar.angle", "--json", str(out))
    doc = json.loads(out.read_text())
    assert doc["modes"] == lin["modes"]
    assert np.array_equal(np.array(doc["A"]), lin["A"])
    with pytest.raises(bondmech.OptionsError, match="--at 'later'"):
        bondmech.load(path).linearize(at="later")
