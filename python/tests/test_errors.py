"""Every exception type with its fields."""

from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pytest

import bondmech
from conftest import SCENES

BAD_MASS = {
    "bodies": [{"name": "b", "mass": -1, "inertia": 1, "points": {"O": [-1, 0]}},
               {"name": "c", "mass": 1, "inertia": "heavy"}],
    "solve": {"t_end": 1},
}


def test_scene_error_lists_every_problem_with_its_path():
    with pytest.raises(bondmech.SceneError) as info:
        bondmech.load(BAD_MASS)
    e = info.value
    assert isinstance(e, bondmech.Error) and isinstance(e, ValueError)
    paths = [p["path"] for p in e.problems]
    assert "bodies[1].inertia" in paths, e.problems
    assert all(set(p) == {"path", "message"} for p in e.problems)
    assert "bodies[1].inertia" in str(e)


def test_scene_error_from_a_bad_value_keeps_the_scene(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    with pytest.raises(bondmech.SceneError) as info:
        scene.set("bodies[bar2].mass", -2)
    assert [p["path"] for p in info.value.problems] == ["bodies[1].mass"]
    assert "set by Scene.set bodies[bar2].mass=-2" in info.value.problems[0]["message"]
    assert scene.sets == [] and scene.to_dict()["bodies"][1]["mass"] == 1.0


def test_scene_error_from_a_bad_path_says_what_is_there(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    with pytest.raises(bondmech.SceneError) as info:
        scene.set("bodies[bar3].mass", 2)
    assert "bar1" in str(info.value) and "bar2" in str(info.value)
    assert len(info.value.problems) == 1


def test_scene_error_from_a_run_argument_names_the_field(double_pendulum_path):
    with pytest.raises(bondmech.SceneError) as info:
        bondmech.load(double_pendulum_path).run(rtol=-1.0)
    assert info.value.problems[0]["path"] == "solve.rtol"
    assert str(info.value).startswith("rtol=")


def test_missing_file_is_a_scene_error(tmp_path):
    with pytest.raises(bondmech.SceneError) as info:
        bondmech.load(tmp_path / "nope.json")
    assert "nope.json" in str(info.value) and len(info.value.problems) == 1


def test_options_error(double_pendulum_path, tmp_path):
    with pytest.raises(bondmech.OptionsError, match="formulation='nope'"):
        bondmech.load(double_pendulum_path).run(formulation="nope")
    # a raw bond graph whose joint row has no closure: ggl needs g(q) and is refused by name
    held = tmp_path / "held_mass.json"
    held.write_text(
        '{"bond_graph": {"elements": ['
        '{"name": "m", "kind": "I", "value": 1.0}, {"name": "v", "kind": "1"},'
        '{"name": "pin", "kind": "Sf", "value": 0.0}],'
        '"bonds": [{"from": "v", "to": "m"}, {"from": "v", "to": "pin"}]},'
        '"solve": {"t_end": 1.0}}'
    )
    with pytest.raises(bondmech.OptionsError, match="formulation 'ggl'.*closures"):
        bondmech.load(held).run(formulation="ggl")
    with pytest.raises(bondmech.OptionsError):
        bondmech.compare(bondmech.load(double_pendulum_path), formulation="decoupled")


def assert_rows_of(partial, full):
    """The partial solution's rows at output times are those of the complete run, to the last
    bit (a budget stop adds a last row at the time reached)."""
    k = int(np.sum(np.isin(partial.t, full.t)))
    assert k >= max(len(partial) - 1, 2)
    assert partial.columns == full.columns
    assert np.array_equal(partial.t[:k], full.t[:k])
    assert np.array_equal(partial.values[:k], full.values[:k])


def test_budget_exceeded_keeps_its_partial_rows(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    full = scene.run()
    with pytest.raises(bondmech.BudgetExceeded) as info:
        scene.run(max_steps=300)
    e = info.value
    assert isinstance(e, bondmech.SolveError) and isinstance(e, bondmech.Error)
    assert e.stopped_by == "max_steps" and "max_steps" in str(e)
    assert 0.0 < e.t_reached < 3.0
    p = e.partial
    assert isinstance(p, bondmech.Solution)
    assert p.summary["completed"] is False and p.summary["t_reached"] == e.t_reached
    assert 2 <= len(p) < len(full)
    # the last row is the state at the time reached, the others are output times
    assert p.t[-1] == e.t_reached
    assert_rows_of(p, full)


def test_wall_clock_budget_is_budget_exceeded(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path).set("solve.output_step", 0.5)
    with pytest.raises(bondmech.BudgetExceeded) as info:
        scene.run(t_end=1e4, max_wall_seconds=0.2)
    assert info.value.stopped_by == "max_wall_seconds"
    assert info.value.t_reached > 0 and len(info.value.partial) >= 1


def test_solve_error_from_a_non_finite_load_keeps_the_rows_before_it():
    scene = bondmech.load(SCENES / "pendulum.json")
    raw = scene.to_dict()
    raw["loads"] = [{"name": "blowup", "type": "torque", "body": raw["bodies"][0]["name"],
                     "value": "1/sqrt(0.25 - t)"}]
    raw["solve"]["t_end"] = 0.5
    with pytest.raises(bondmech.SolveError) as info:
        bondmech.load(raw).run()
    e = info.value
    assert not isinstance(e, bondmech.BudgetExceeded)
    assert e.stopped_by == "solver_error"
    assert "loads[0].value (load 'blowup'" in str(e) and "t = 0.25" in e.cause
    # the rows before the blow-up are kept, and they are the rows of a run that stops before it
    assert e.t_reached == pytest.approx(0.25, abs=1e-9)
    p = e.partial
    assert not p.summary["completed"] and 0.24 in p.t and p.t[-1] <= 0.25
    raw["solve"]["t_end"] = 0.24
    before = bondmech.load(raw).run()
    # (a run that ends at 0.24 stops its integrator there: its last row is not interpolated)
    assert np.array_equal(p.t[:24], before.t[:24])
    assert np.array_equal(p.values[:24], before.values[:24])


def test_ctrl_c_interrupts_a_long_solve(double_pendulum_path):
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals are handled on the main thread")
    scene = bondmech.load(double_pendulum_path).set("solve.output_step", 0.5)
    # the test sets its own SIGINT disposition: started with SIGINT ignored (a background job
    # of a non-interactive shell, issue 51) Python installs no KeyboardInterrupt handler
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            scene.run(t_end=1e4, rtol=1e-10)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    # it stopped soon after the signal, long before the 10⁴ s of motion
    assert time.monotonic() - start < 5.0
