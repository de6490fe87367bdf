"""The arrays equal the command line's CSV to the last digit (and its summary, but for timing)."""

from __future__ import annotations

import csv
import io
import json

import numpy as np

import bondmech
from conftest import SCENES

TIMING = {"cpu_seconds", "build_cpu_seconds"}


def parse_csv(text: str):
    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], rows[1:]
    data = np.array([[float(x) for x in r] for r in body], dtype=np.float64)
    return header, data


def check_equal(sol, csv_text, summary_text):
    header, data = parse_csv(csv_text)
    assert header == ["t", *sol.columns]
    assert np.array_equal(sol.t, data[:, 0])
    # bit for bit: the CSV prints 17 significant digits, which round-trip every double
    assert np.array_equal(sol.values, data[:, 1:]), np.max(np.abs(sol.values - data[:, 1:]))
    assert sol.to_csv() == csv_text
    a, b = dict(sol.summary), json.loads(summary_text)
    for k in TIMING:
        a.pop(k, None)
        b.pop(k, None)
    assert a == b


def test_double_pendulum_equals_the_cli_csv(cli, tmp_path, double_pendulum_path):
    out, summ = tmp_path / "run.csv", tmp_path / "summary.json"
    cli("run", str(double_pendulum_path), "--out", str(out), "--summary", str(summ))
    sol = bondmech.load(double_pendulum_path).run()
    assert len(sol) == 301
    check_equal(sol, out.read_text(), summ.read_text())


def test_flags_and_sets_equal_the_cli(cli, tmp_path):
    out, summ = tmp_path / "run.csv", tmp_path / "summary.json"
    scene_path = SCENES / "slider_crank.json"
    cli("run", str(scene_path), "--set", "bodies[0].mass=0.7", "--t-end", "0.4",
        "--formulation", "index1", "--rtol", "1e-7", "--reactions",
        "--out", str(out), "--summary", str(summ))
    scene = bondmech.load(scene_path).set("bodies[0].mass", 0.7)
    sol = scene.run(t_end=0.4, formulation="index1", rtol=1e-7, reactions=True)
    check_equal(sol, out.read_text(), summ.read_text())


def test_raw_bond_graph_equals_the_cli(cli, tmp_path):
    out, summ = tmp_path / "run.csv", tmp_path / "summary.json"
    scene_path = SCENES / "bg_mass_spring_damper.json"
    cli("run", str(scene_path), "--out", str(out), "--summary", str(summ))
    check_equal(bondmech.load(scene_path).run(), out.read_text(), summ.read_text())


def test_compare_equals_the_cli_compare_json(cli, tmp_path, double_pendulum_path):
    out = tmp_path / "compare.json"
    cli("compare", str(double_pendulum_path), "--t-end", "0.3", "--joint-stiffness", "1e7",
        "--json", str(out))
    ours = bondmech.compare(bondmech.load(double_pendulum_path), joint_stiffness=1e7, t_end=0.3)
    theirs = json.loads(out.read_text())
    for side in ("dae", "decoupled"):
        for k in TIMING:
            ours[side].pop(k, None)
            theirs[side].pop(k, None)
    # the verdict's CPU ratio (and the reason quoting it) are timings too
    for doc in (ours, theirs):
        for k in ("cpu_ratio", "reason"):
            doc.get("verdict", {}).pop(k, None)
    assert ours == theirs
    assert ours["decoupled"]["formulation"] == "decoupled"


def test_graph_equals_the_cli_graph(cli, double_pendulum_path):
    scene = bondmech.load(double_pendulum_path)
    assert bondmech.graph(scene) == cli("graph", str(double_pendulum_path)).stdout
    causality = cli("graph", str(double_pendulum_path), "--causality").stdout
    assert bondmech.graph(scene, causality=True) == json.loads(causality)
