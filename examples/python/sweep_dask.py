"""A ``bondmech sweep --vary`` parameter sweep as Dask tasks on a ``dask.distributed`` cluster.

Each point of the sweep is one task: the shard ``k+1/n`` of an ``n``-point sweep, solved on a
worker by the same library call as ``bondmech.sweep`` (its report as JSON), and the reports are
merged by the library's ``sweep-merge`` (which refuses a missing or repeated point). The table
equals ``bondmech.sweep``'s to the last digit, except the timing column ``cpu_seconds``.

    python examples/python/sweep_dask.py                      # a LocalCluster on this machine
    python examples/python/sweep_dask.py tcp://scheduler:8786 # an existing cluster (docs/scale.md)

The workers need ``bondmech`` installed (``pip install ./python``) and the scene travels with the
task (a ``Scene`` pickles as its JSON text and its ``set`` assignments), so no shared file
system is needed.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Dict, Mapping, Optional, Sequence

import numpy as np

import bondmech

ROOT = Path(__file__).resolve().parents[2]


def _point(scene: bondmech.Scene, vary: Mapping[str, Sequence[Any]], k: int, n: int,
           columns: Optional[Sequence[str]], t_end: Optional[float]) -> str:
    """One task: point ``k`` of ``n`` (shard ``k+1/n``), on one thread of the worker."""
    return bondmech.sweep_shard(scene, vary, (k + 1, n), columns=columns, t_end=t_end, workers=1)


def sweep_dask(client, scene: bondmech.Scene, vary: Mapping[str, Sequence[Any]],
               columns: Optional[Sequence[str]] = None,
               t_end: Optional[float] = None) -> Dict[str, np.ndarray]:
    """``bondmech.sweep(scene, vary, columns, t_end=t_end)`` with one Dask task per point."""
    n = bondmech.sweep_points(vary)
    vary = {path: list(values) for path, values in vary.items()}
    scene_future = client.scatter(scene, broadcast=True)
    futures = [
        client.submit(_point, scene_future, vary, k, n, columns, t_end, key=f"bondmech-point-{k}-of-{n}",
                      pure=False)
        for k in range(n)
    ]
    return bondmech.merge_sweep(client.gather(futures))


def main(address: Optional[str] = None) -> Dict[str, np.ndarray]:
    from dask.distributed import Client, LocalCluster

    scene = bondmech.load(ROOT / "scenes" / "double_pendulum.json")
    vary = {"bodies[bar2].mass": [0.5, 1.0, 2.0], "gravity": [[0.0, -9.81], [0.0, -1.62]]}
    if address:
        client = Client(address)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        table = sweep_dask(client, scene, vary, columns=["bar2.A.x", "bar2.A.y"], t_end=1.0)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    for k in range(len(table["index"])):
        print(f"point {table['index'][k]}: bar2 mass {table['bodies[bar2].mass'][k]}, "
              f"gravity {table['gravity'][k]}: {table['steps'][k]} steps, "
              f"tip at ({table['final.bar2.A.x'][k]:.6f}, {table['final.bar2.A.y'][k]:.6f})")
    return table


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
