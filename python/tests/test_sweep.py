"""Parameter sweeps: bondmech.sweep (the --vary table), its shards, and the Dask sweep."""

from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest

import bondmech
from conftest import ROOT

VARY = {"bodies[bar2].mass": [0.5, 1.0, 2.0], "gravity": [[0.0, -9.81], [0.0, -1.62]]}
TIMING = set(bondmech.TIMING_COLUMNS)


def assert_tables_equal(a, b):
    assert list(a) == list(b)
    for key in a:
        if key in TIMING:
            continue
        if a[key].dtype == object:
            assert list(a[key]) == list(b[key]), key
        else:
            assert np.array_equal(a[key], b[key], equal_nan=True), key


def test_sweep_is_the_vary_table_and_each_point_is_a_run(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    table = bondmech.sweep(scene, VARY, columns=["bar2.A.x", "bar2.A.y"], t_end=0.5)
    assert list(table["index"]) == list(range(6))
    assert list(table)[:3] == ["index", "bodies[bar2].mass", "gravity"]
    assert table["bodies[bar2].mass"].dtype == np.float64
    assert list(table["bodies[bar2].mass"]) == [0.5, 0.5, 1.0, 1.0, 2.0, 2.0]
    assert table["gravity"][1] == [0.0, -1.62]
    assert all(f is None for f in table["failure"])
    assert {"final.bar2.A.x", "final.bar2.A.y", "steps", "cpu_seconds", "t_final"} <= set(table)
    # point 3 (mass 1, lunar gravity) is a plain run with those values, to the last bit
    sol = (bondmech.load(double_pendulum_path).set("bodies[bar2].mass", 1.0)
           .set("gravity", [0.0, -1.62]).run(t_end=0.5))
    assert table["final.bar2.A.y"][3] == sol["bar2.A.y"][-1]
    assert table["steps"][3] == sol.summary["steps"]


def test_sweep_results_do_not_depend_on_the_workers(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    vary = {"bodies[bar2].mass": [0.5, 2.0]}
    a = bondmech.sweep(scene, vary, t_end=0.3, workers=1)
    b = bondmech.sweep(scene, vary, t_end=0.3, workers=2)
    assert_tables_equal(a, b)


def test_shards_merge_into_the_whole_sweep_and_refuse_a_missing_one(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    vary = {"bodies[bar2].mass": [0.5, 1.0, 2.0]}
    whole = bondmech.sweep(scene, vary, t_end=0.3)
    parts = [bondmech.sweep_shard(scene, vary, (i, 2), t_end=0.3) for i in (2, 1)]
    assert_tables_equal(bondmech.merge_sweep(parts), whole)
    with pytest.raises(bondmech.OptionsError, match="1/2|missing"):
        bondmech.merge_sweep(parts[:1])
    # the shard's report is the command line's vary.json; its CSV is vary.csv
    assert bondmech.sweep_csv(parts[0]).startswith("index,bodies[bar2].mass,failure,")
    assert json.loads(parts[0])["shard"] is not None


def test_sweep_refuses_bad_arguments(double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    with pytest.raises(bondmech.OptionsError):
        bondmech.sweep(scene, {})
    with pytest.raises(bondmech.SceneError):
        bondmech.sweep(scene, {"bodies[bar9].mass": [1.0]})
    with pytest.raises(bondmech.OptionsError, match="nope"):
        bondmech.sweep(scene, {"bodies[bar2].mass": [1.0]}, columns=["nope"], t_end=0.1)


def load_example():
    path = ROOT / "examples" / "python" / "sweep_dask.py"
    spec = importlib.util.spec_from_file_location("sweep_dask", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_dask_sweep_equals_bondmech_sweep(double_pendulum_path):
    distributed = pytest.importorskip("dask.distributed")
    example = load_example()
    scene = bondmech.load(double_pendulum_path).set("solve.rtol", 1e-9)
    columns = ["bar2.A.x", "bar2.A.y", "energy"]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        table = example.sweep_dask(client, scene, VARY, columns=columns, t_end=0.5)
    expected = bondmech.sweep(scene, VARY, columns=columns, t_end=0.5)
    assert len(table["index"]) == 6
    assert_tables_equal(table, expected)
