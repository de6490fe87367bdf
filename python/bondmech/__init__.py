"""bondmech from Python: mechanisms as bond graphs, solved with SUNDIALS (IDA, CVODE, ARKODE).

The package wraps the Rust library's public API (a PyO3 extension, ``bondmech._native``): the
same scenes, the same solvers, the same numbers as the ``bondmech`` command line, as numpy
arrays. Every solve releases the GIL, so threads solve in parallel.

>>> import bondmech
>>> scene = bondmech.load("scenes/double_pendulum.json")      # or a dict
>>> sol = scene.set("bodies[bar2].mass", 2.0).run(t_end=1.0)   # --set, --t-end
>>> sol.t.shape, sol["bar2.A.y"][-1], sol.summary["steps"]      # doctest: +SKIP

See docs/python.md.
"""

from __future__ import annotations

import itertools
import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ._errors import BudgetExceeded, Error, OptionsError, SceneError, SolveError
from ._native import (
    Endpoint,
    Ground,
    Mechanism,
    PlanarBody,
    Scene,
    Solution,
    SpatialBody,
    SpringDamper,
    compare,
    graph,
)
from . import _native
from ._util import finite_or_nan, is_number, to_json

__version__ = _native._versions()[0]
#: The SUNDIALS version the extension runs on (major, minor, patch).
SUNDIALS_VERSION: Tuple[int, int, int] = tuple(_native._versions()[1])  # type: ignore[assignment]

__all__ = [
    "load",
    "Scene",
    "Solution",
    "compare",
    "graph",
    "sweep",
    "sweep_shard",
    "merge_sweep",
    "sweep_points",
    "sweep_csv",
    "TIMING_COLUMNS",
    "SUNDIALS_VERSION",
    "Mechanism",
    "PlanarBody",
    "SpatialBody",
    "Ground",
    "Endpoint",
    "SpringDamper",
    "Error",
    "SceneError",
    "OptionsError",
    "SolveError",
    "BudgetExceeded",
]


def load(source: Union[str, "os.PathLike[str]", Mapping[str, Any]], name: Optional[str] = None) -> Scene:
    """A scene from a file path (JSON, scene format v1) or a dict (the same content).

    A dict may hold a mechanism (``bodies``, ``joints``, ...) or a raw ``"bond_graph"``
    (``elements`` and ``bonds``). ``name`` defaults to the file stem (``"scene"`` for a dict).
    Raises :class:`SceneError` listing every problem with its JSON path.
    """
    if isinstance(source, Mapping):
        return Scene.from_json(to_json(dict(source)), name or "scene")
    if isinstance(source, (str, os.PathLike)):
        scene = Scene.from_path(os.fspath(source))
        if name is not None:
            scene.set("name", name)
        return scene
    raise TypeError(f"load: a path or a dict, got {type(source).__name__}")


# ----------------------------------------------------------------------------- sweeps

#: The columns of a sweep table that measure time (they differ between runs of the same sweep).
TIMING_COLUMNS = ("cpu_seconds",)


def _vary_args(vary: Mapping[str, Sequence[Any]]) -> List[str]:
    if not isinstance(vary, Mapping) or not vary:
        raise OptionsError("vary: a dict {path: [values]} with at least one path")
    out = []
    for path, values in vary.items():
        values = list(values)
        out.append(f"{path}={to_json(values)}")
    return out


def sweep_points(vary: Mapping[str, Sequence[Any]]) -> int:
    """The number of points of a sweep over ``vary`` (the cartesian product)."""
    n = 1
    for values in vary.values():
        n *= len(list(values))
    return n


def _table(report: Dict[str, Any]) -> Dict[str, np.ndarray]:
    """A sweep report (``vary.json``) as the ``vary.csv`` table: one numpy array per column."""
    points = report["points"]
    spec = report["spec"]
    table: Dict[str, np.ndarray] = {"index": np.array([p["index"] for p in points], dtype=np.int64)}
    for i, v in enumerate(spec["vary"]):
        values = [p["values"][i] for p in points]
        if all(is_number(x) for x in values):
            table[v["path"]] = np.array(values, dtype=np.float64)
        else:
            arr = np.empty(len(values), dtype=object)
            arr[:] = values
            table[v["path"]] = arr
    failure = np.empty(len(points), dtype=object)
    failure[:] = [p["failure"] for p in points]
    table["failure"] = failure
    table["formulation"] = np.array([p["formulation"] for p in points], dtype=object)
    for key in ("steps", "residual_evals", "jacobian_evals", "error_test_failures"):
        table[key] = np.array([p[key] for p in points], dtype=np.int64)
    keys = ["cpu_seconds", "max_constraint_error", "energy_drift"]
    if spec.get("reference") is not None:
        keys.append("error")
    keys.append("t_final")
    for key in keys:
        table[key] = np.array([finite_or_nan(p[key]) for p in points], dtype=np.float64)
    columns: List[str] = []
    for p in points:
        for f in p["final_values"]:
            if f["column"] not in columns:
                columns.append(f["column"])
    for c in columns:
        col = []
        for p in points:
            v = next((f["value"] for f in p["final_values"] if f["column"] == c), None)
            col.append(finite_or_nan(v))
        table[f"final.{c}"] = np.array(col, dtype=np.float64)
    return table


def sweep_shard(
    scene: Scene,
    vary: Mapping[str, Sequence[Any]],
    shard: Tuple[int, int],
    columns: Optional[Sequence[str]] = None,
    t_end: Optional[float] = None,
    workers: Optional[int] = 1,
) -> str:
    """One slice of a sweep (``bondmech sweep --vary ... --shard i/n``): the points ``k`` with
    ``k mod n = i - 1``, as the JSON report the command line writes (``vary.json``). The
    building block of a distributed sweep: run the ``n`` shards anywhere (Dask tasks, ...)
    and combine them with :func:`merge_sweep`."""
    return _native._sweep(
        scene, _vary_args(vary), list(columns) if columns is not None else None, workers, t_end,
        tuple(shard),
    )


def merge_sweep(reports: Sequence[str]) -> Dict[str, np.ndarray]:
    """The table of a whole sweep from the JSON reports of all its shards (any order);
    refuses shards of another sweep, missing or repeated ones (``bondmech sweep-merge``)."""
    return _table(json.loads(_native._sweep_merge(list(reports))))


def sweep(
    scene: Scene,
    vary: Mapping[str, Sequence[Any]],
    columns: Optional[Sequence[str]] = None,
    workers: Optional[int] = None,
    t_end: Optional[float] = None,
) -> Dict[str, np.ndarray]:
    """A parameter sweep (``bondmech sweep --vary``): every combination of the values of
    ``vary`` (``{path: [values]}``, paths as in :meth:`Scene.set`), solved on ``workers``
    threads (all cores by default; results equal a serial run's), without the GIL.

    Returns the ``vary.csv`` table as a dict of numpy arrays: ``index``, one array per varied
    path, ``failure`` (``None`` or the error), ``formulation``, ``steps``, ``residual_evals``,
    ``jacobian_evals``, ``error_test_failures``, ``cpu_seconds``, ``max_constraint_error``,
    ``energy_drift``, ``t_final`` and ``final.<column>`` for each output column (or each of
    ``columns``).
    """
    report = _native._sweep(
        scene, _vary_args(vary), list(columns) if columns is not None else None, workers, t_end,
        None,
    )
    return _table(json.loads(report))


def sweep_csv(report: str) -> str:
    """The ``vary.csv`` text of a sweep report (JSON, from :func:`sweep_shard`)."""
    return _native._sweep_csv(report)
