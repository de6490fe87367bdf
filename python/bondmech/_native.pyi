"""Type stubs of the native module ``bondmech._native`` (PyO3)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

SIGNAL_CHECK_SECONDS: float

class Solution:
    """A solved trajectory: one row per output time (``bondmech run``'s CSV as numpy arrays)."""

    @property
    def t(self) -> npt.NDArray[np.float64]:
        """Output times (s), 1-D, read-only."""
    @property
    def columns(self) -> List[str]:
        """Column names without ``t``, in the CSV's order."""
    @property
    def values(self) -> npt.NDArray[np.float64]:
        """All columns, rows × columns, read-only."""
    @property
    def summary(self) -> Dict[str, Any]:
        """The solver summary (``--summary`` JSON) as a dict."""
    def summary_json(self) -> str:
        """The summary as the JSON text ``bondmech run --summary`` writes."""
    def to_csv(self) -> str:
        """The CSV text ``bondmech run --out`` writes, byte for byte."""
    def to_pandas(self) -> Any:
        """A ``pandas.DataFrame`` of the columns indexed by ``t`` (needs pandas)."""
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]:
        """One column over time (``"t"``: the times); ``KeyError`` naming the columns."""
    def __contains__(self, name: str) -> bool: ...
    def __len__(self) -> int: ...

class Scene:
    """A validated scene: a mechanism or a raw bond graph."""

    @staticmethod
    def from_path(path: str) -> "Scene": ...
    @staticmethod
    def from_json(text: str, name: str = "scene") -> "Scene": ...
    @property
    def name(self) -> str: ...
    @property
    def is_bond_graph(self) -> bool: ...
    @property
    def sets(self) -> List[str]:
        """The ``set`` assignments so far, as ``PATH=JSON`` text."""
    def set(self, path: str, value: Any) -> "Scene":
        """Changes one field as ``bondmech run --set PATH=JSON`` does; returns the scene."""
    def to_dict(self) -> Dict[str, Any]: ...
    def to_json(self) -> str: ...
    def run(
        self,
        formulation: Optional[str] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        t_end: Optional[float] = None,
        reactions: bool = False,
        linear_solver: Optional[str] = None,
        max_wall_seconds: Optional[float] = None,
        max_steps: Optional[int] = None,
        joint_stiffness: Optional[float] = None,
    ) -> Solution:
        """Solves the scene (the GIL is released); raises SceneError, OptionsError,
        SolveError or BudgetExceeded."""
    def equilibrium(self) -> Dict[str, Any]:
        """The static equilibrium nearest the scene's configuration (the ``bondmech
        equilibrium --json`` document): converged, iterations, residual, coordinates,
        reactions, drivers, stable, stability ("stable", "neutral", "unstable"),
        stiffness_eigenvalues (omega^2, 1/s^2, mass-normalised), cpu_seconds."""
    def linearize(
        self,
        at: str = "equilibrium",
        outputs: Optional[List[str]] = None,
        states: Optional[List[str]] = None,
    ) -> Dict[str, Any]:
        """The linear model x' = A x + B u, y = C x + D u about an operating point
        ("equilibrium" or "t=T"), the ``bondmech linearize --json`` document with A, B, C, D
        as 2-D numpy arrays: at, t, operating_point, states, inputs, outputs, A, B, C, D,
        equilibrium, eigenvalues, modes (eigenvalue, omega_n, frequency_hz, damping_ratio,
        multiplicity, shape; empty about a moving operating point), notes, cpu_seconds."""
    def sensitivity(
        self, params: List[str], t_end: Optional[float] = None
    ) -> Dict[str, Any]:
        """Forward sensitivities (IDAS, exact dF/dp) to scene parameters given as paths
        ("bodies[bar2].mass"): t, columns, values (the run), sensitivities
        ({"d(<column>)/d(<path>)": 1-D array}), warnings."""
    def fit(
        self, data: Any, params: List[str], columns: Optional[List[str]] = None
    ) -> Dict[str, Any]:
        """Scene parameters fitted to data (CSV text, a dict of columns or a pandas
        DataFrame with "t" and run columns) by Levenberg-Marquardt on the exact
        sensitivities: the ``bondmech fit --json`` document (converged, iterations,
        parameters, std_errors, covariance, correlation, residual_rms, ...)."""

def compare(
    scene: Scene,
    joint_stiffness: Optional[float] = None,
    formulation: Optional[str] = None,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    t_end: Optional[float] = None,
    reactions: bool = False,
    linear_solver: Optional[str] = None,
    max_wall_seconds: Optional[float] = None,
    max_steps: Optional[int] = None,
) -> Dict[str, Any]:
    """``bondmech compare --json``: the DAE and its decoupled twin, compared."""

def graph(scene: Scene, causality: bool = False, decoupled: bool = False) -> Union[str, Dict[str, Any]]:
    """``bondmech graph``: DOT text, or the causality report (a dict) with ``causality=True``."""

def _sweep(
    scene: Scene,
    vary: List[str],
    columns: Optional[List[str]] = None,
    workers: Optional[int] = None,
    t_end: Optional[float] = None,
    shard: Optional[Tuple[int, int]] = None,
) -> str: ...
def _sweep_merge(reports: List[str]) -> str: ...
def _sweep_csv(report: str) -> str: ...
def _library_cpu_seconds(scene: Scene, repeats: int = 1) -> Tuple[float, int]: ...
def _versions() -> Tuple[str, Tuple[int, int, int]]: ...

Point = Union[str, Sequence[float]]
End = Union["Endpoint", str, Tuple[str, Point]]
LoadValue = Union[float, Sequence[float], str, Sequence[Union[str, float]], Dict[str, Any]]

class Endpoint:
    @property
    def body(self) -> str: ...

class Ground:
    @staticmethod
    def at(coords: Sequence[float]) -> Endpoint: ...

class PlanarBody:
    def __init__(self, name: str, mass: float, inertia: float) -> None: ...
    @staticmethod
    def bar(name: str, mass: float, length: float) -> "PlanarBody": ...
    @staticmethod
    def point_mass(name: str, mass: float) -> "PlanarBody": ...
    def inertia(self, inertia: float) -> "PlanarBody": ...
    def point(self, name: str, coords: Sequence[float]) -> "PlanarBody": ...
    def at(self, position: Sequence[float], angle: float = 0.0) -> "PlanarBody": ...
    def velocity(self, velocity: Sequence[float]) -> "PlanarBody": ...
    def angular_velocity(self, omega: float) -> "PlanarBody": ...
    def frame(self, name: str) -> "PlanarBody": ...

class SpatialBody:
    def __init__(self, name: str, mass: float, principal_inertia: Sequence[float]) -> None: ...
    def point(self, name: str, coords: Sequence[float]) -> "SpatialBody": ...
    def at(self, position: Sequence[float], cardan: Sequence[float] = ...) -> "SpatialBody": ...
    def velocity(self, velocity: Sequence[float]) -> "SpatialBody": ...
    def angular_velocity(self, omega: Sequence[float]) -> "SpatialBody": ...
    def frame(self, name: str) -> "SpatialBody": ...

class SpringDamper:
    def __init__(self, name: str, a: End, b: End, stiffness: float) -> None: ...
    def rest_length(self, rest_length: float) -> "SpringDamper": ...
    def damping(self, damping: float) -> "SpringDamper": ...

class Mechanism:
    @staticmethod
    def planar() -> "Mechanism": ...
    @staticmethod
    def spatial() -> "Mechanism": ...
    def name(self, name: str) -> "Mechanism": ...
    def description(self, text: str) -> "Mechanism": ...
    def gravity(self, g: Sequence[float]) -> "Mechanism": ...
    def body(self, body: Union[PlanarBody, SpatialBody]) -> "Mechanism": ...
    def revolute(self, name: str, a: End, b: End) -> "Mechanism": ...
    def prismatic(self, name: str, a: End, b: End, axis: Sequence[float]) -> "Mechanism": ...
    def spherical(self, name: str, a: End, b: End) -> "Mechanism": ...
    def hinge(self, name: str, a: End, b: End, axis: Sequence[float]) -> "Mechanism": ...
    def weld(self, name: str, a: End, b: End) -> "Mechanism": ...
    def spring(self, spring: SpringDamper) -> "Mechanism": ...
    def force(self, name: str, at: End, value: LoadValue) -> "Mechanism": ...
    def torque(self, name: str, body: str, value: LoadValue) -> "Mechanism": ...
    def output(self, output: str) -> "Mechanism": ...
    def event(self, name: str, when: str, direction: str = "both", action: str = "record") -> "Mechanism": ...
    def t_end(self, t_end: float) -> "Mechanism": ...
    def output_step(self, step: float) -> "Mechanism": ...
    def tolerances(self, rtol: float, atol: float) -> "Mechanism": ...
    def formulation(self, name: str) -> "Mechanism": ...
    def build(self) -> Scene: ...
