"""Overhead of the Python layer: thread CPU time of ``Scene.run()`` against the library call it
wraps (the scene's options written in, ``Model::new``, ``Model::solve``), timed in Rust on the
same thread by ``bondmech._native._library_cpu_seconds`` — same build, same scene.

    python python/benches/overhead.py [SCENE.json] [--repeats N] [--rounds R]

Rounds alternate the two (library, Python, library, Python, ...) so that a change of machine
load hits both; the ratio is of the medians of the per-solve CPU times.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import bondmech
from bondmech import _native

ROOT = Path(__file__).resolve().parents[2]


def measure(scene_path, repeats: int = 10, rounds: int = 5) -> dict:
    scene = bondmech.load(scene_path)
    scene.run()  # warm-up: page in the code, allocate
    lib, py = [], []
    steps = None
    for _ in range(rounds):
        cpu, steps = _native._library_cpu_seconds(scene, repeats)
        lib.append(cpu / repeats)
        t0 = time.thread_time()
        for _ in range(repeats):
            sol = scene.run()
        py.append((time.thread_time() - t0) / repeats)
        assert sol.summary["steps"] == steps
    lib_med, py_med = statistics.median(lib), statistics.median(py)
    return {
        "scene": str(scene_path),
        "steps": steps,
        "rows": len(sol),
        "library_cpu_s": lib_med,
        "python_cpu_s": py_med,
        "ratio": py_med / lib_med,
        "repeats": repeats,
        "rounds": rounds,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "double_pendulum.json"))
    ap.add_argument("--repeats", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    r = measure(a.scene, a.repeats, a.rounds)
    print(
        f"{r['scene']}: {r['steps']} steps, {r['rows']} rows; per solve (median of {r['rounds']} "
        f"rounds of {r['repeats']}): library {r['library_cpu_s'] * 1e3:.2f} ms CPU, "
        f"Scene.run() {r['python_cpu_s'] * 1e3:.2f} ms CPU, ratio {r['ratio']:.3f}"
    )
    if r["ratio"] > 1.1:
        raise SystemExit(f"overhead ratio {r['ratio']:.3f} > 1.1")


if __name__ == "__main__":
    main()
