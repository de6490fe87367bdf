"""Overhead: a Python Scene.run() of the double pendulum costs at most 1.1× the CPU of the
library call it wraps (the same scene, Model::new and Model::solve, timed in Rust)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))

from overhead import measure  # noqa: E402


def test_scene_run_costs_at_most_1_1_times_the_library_call(double_pendulum_path):
    result = measure(double_pendulum_path, repeats=5, rounds=3)
    print(result)
    assert result["ratio"] <= 1.1, result
