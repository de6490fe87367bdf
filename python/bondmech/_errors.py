"""The exceptions bondmech raises (the library's typed errors, with their fields)."""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional


class Error(Exception):
    """Base class of every bondmech error."""


class SceneError(Error, ValueError):
    """The scene (or a ``set``, or a ``run`` argument written into its ``solve`` section) is
    invalid.

    ``problems`` lists every problem found, each ``{"path": ..., "message": ...}`` with the JSON
    path of the field (``bodies[0].mass``, ``solve.rtol``; empty for the whole document).
    """

    def __init__(self, message: str, problems: List[Dict[str, str]]):
        super().__init__(message)
        self.problems: List[Dict[str, str]] = problems


class OptionsError(Error, ValueError):
    """An option that cannot apply (an unknown formulation, ``ggl`` on a raw bond graph without closures,
    a sweep that is refused, ...)."""


class SolveError(Error, RuntimeError):
    """The solve stopped before its last output time.

    ``t_reached`` is the time the integrator reached (``nan`` when it failed before its first
    step, e.g. in the consistent initialisation); ``partial`` is a :class:`Solution` with the
    rows computed up to then (``None`` when nothing was kept); ``stopped_by`` names the budget
    that ran out (``"max_steps"``, ``"max_wall_seconds"``) or is ``None``; ``cause`` is the
    solver's own message.
    """

    def __init__(
        self,
        message: str,
        t_reached: float = math.nan,
        partial: Optional[Any] = None,
        stopped_by: Optional[str] = None,
        cause: str = "",
    ):
        super().__init__(message)
        self.t_reached: float = t_reached
        self.partial = partial
        self.stopped_by: Optional[str] = stopped_by
        self.cause: str = cause


class BudgetExceeded(SolveError):
    """A budget (``max_wall_seconds``, ``max_steps``) ran out: a :class:`SolveError` whose
    ``stopped_by`` names it; ``partial`` holds the rows computed until then."""
