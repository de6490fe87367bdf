"""The GIL is released during a solve: Python threads solve in parallel.

Two threads solving at once must take at most 1.3× the wall time of one solve (on two cores).
The solve is made long (about one second of CPU) and the measurement is tried up to three
times: a solve that held the GIL would take twice as long for two threads every time, never
1.3×. On a machine whose cores are busy with other work the comparison says nothing about the
GIL (two processes, each with its own GIL, are not faster than two threads either); the test then
says so and skips, and two
checks that hold on any machine remain: the main thread runs while a solve is in progress, and
two threads solving at once take no longer than two processes (each with its own GIL) doing
the same."""

from __future__ import annotations

import os
import threading
import time

import numpy as np
import pytest

import bondmech

OPTS = dict(rtol=1e-10, atol=1e-12)


def long_scene(double_pendulum_path):
    return bondmech.load(double_pendulum_path).set("solve.output_step", 0.05)


def calibrated_t_end(scene, cpu_seconds=1.0):
    """A horizon for which one solve takes about `cpu_seconds` of CPU here."""
    t0 = time.thread_time()
    scene.run(t_end=20.0, **OPTS)
    per_second = (time.thread_time() - t0) / 20.0
    return float(np.clip(cpu_seconds / max(per_second, 1e-5), 5.0, 2000.0))


def solve_in_threads(scene, n, t_end):
    """Wall time of `n` threads solving at once, their solutions and thread CPU times."""
    results, cpu, errors = [None] * n, [0.0] * n, []

    def work(i):
        try:
            c0 = time.thread_time()
            results[i] = scene.run(t_end=t_end, **OPTS)
            cpu[i] = time.thread_time() - c0
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(n)]
    t0 = time.perf_counter()
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    wall = time.perf_counter() - t0
    assert not errors, errors
    return wall, results, cpu


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores")
def test_two_threads_take_at_most_1_3_times_one_solve(double_pendulum_path):
    scene = long_scene(double_pendulum_path)
    t_end = calibrated_t_end(scene)
    attempts = []
    for _ in range(3):
        one, (alone,), (cpu1,) = solve_in_threads(scene, 1, t_end)
        two, (a, b), cpu2 = solve_in_threads(scene, 2, t_end)
        # the threads computed what the lone solve did
        assert np.array_equal(a.values, alone.values) and np.array_equal(b.values, alone.values)
        # what the machine gives two solves right now: two processes (each its own GIL)
        procs = span_in_processes(scene, t_end, 2)
        attempts.append(dict(one=one, two=two, ratio=two / one, processes=procs,
                             process_ratio=procs / one, cpu_one=cpu1, cpu_two=cpu2))
        if two <= 1.3 * one:
            break
    print(f"t_end {t_end:.0f} s of motion:", attempts)
    best = min(attempts, key=lambda r: r["ratio"])
    # the machine ran two solves in parallel at least once (two processes within 1.2× one)
    parallel = any(r["process_ratio"] <= 1.2 for r in attempts)
    if best["ratio"] > 1.3 and not parallel:
        pytest.skip("the cores are busy with other work: two processes took "
                    f"{[round(r['process_ratio'], 2) for r in attempts]}× one solve, so two "
                    "threads cannot be timed against one here")
    assert best["ratio"] <= 1.3, attempts


def test_python_runs_while_a_solve_is_in_progress(double_pendulum_path):
    # independent of the number of cores and of the load: with the GIL held during the solve,
    # the main thread could not run at all until the solve ended
    scene = long_scene(double_pendulum_path)
    t_end = calibrated_t_end(scene, cpu_seconds=0.5)
    done = threading.Event()
    worker = threading.Thread(target=lambda: (scene.run(t_end=t_end, **OPTS), done.set()))
    ticks = 0
    worker.start()
    start = time.perf_counter()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    elapsed = time.perf_counter() - start
    worker.join()
    assert elapsed > 0.1
    # about one tick per 1-2 ms while the solve runs
    assert ticks > 0.1 * elapsed / 0.001, (ticks, elapsed)


def _solve_after_barrier(scene, t_end, barrier, out):
    """In a thread or a process: one solve started with the others; its start and end times."""
    barrier.wait()
    t0 = time.time()
    scene.run(t_end=t_end, **OPTS)
    out.put((t0, time.time()))


def _span(out, n):
    spans = [out.get(timeout=600) for _ in range(n)]
    return max(e for _, e in spans) - min(s for s, _ in spans)


def span_in_processes(scene, t_end, n):
    """Wall time of `n` processes solving at once (from the first start to the last end)."""
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    barrier, out = ctx.Barrier(n), ctx.Queue()
    procs = [ctx.Process(target=_solve_after_barrier, args=(scene, t_end, barrier, out))
             for _ in range(n)]
    for p in procs:
        p.start()
    span = _span(out, n)
    for p in procs:
        p.join()
        assert p.exitcode == 0
    return span


def test_two_threads_are_as_fast_as_two_processes(double_pendulum_path):
    """Load-independent: two threads solving at once take no longer than two processes doing
    the same (each process has its own GIL), whatever else the machine is doing. With the GIL
    held during a solve, the threads would take twice as long."""
    import queue

    scene = long_scene(double_pendulum_path)
    t_end = calibrated_t_end(scene, cpu_seconds=0.5)
    attempts = []
    for _ in range(3):
        barrier, out = threading.Barrier(2), queue.Queue()
        threads = [threading.Thread(target=_solve_after_barrier, args=(scene, t_end, barrier, out))
                   for _ in range(2)]
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        in_threads = _span(out, 2)
        in_processes = span_in_processes(scene, t_end, 2)
        attempts.append((in_threads, in_processes, in_threads / in_processes))
        if in_threads <= 1.3 * in_processes:
            break
    print("threads, processes, ratio:", attempts)
    assert min(r for *_, r in attempts) <= 1.3, attempts
