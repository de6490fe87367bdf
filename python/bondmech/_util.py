"""Conversions between Python values and the JSON the library reads."""

from __future__ import annotations

import json
import math
from typing import Any


def _plain(value: Any) -> Any:
    """numpy scalars and arrays (and tuples) as plain Python values."""
    if hasattr(value, "tolist") and callable(value.tolist):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON-able")


def to_json(value: Any) -> str:
    """``json.dumps`` for scene values: numpy scalars and arrays accepted, NaN and infinities
    refused (a scene holds finite numbers only)."""
    try:
        return json.dumps(value, default=_plain, allow_nan=False)
    except ValueError as e:
        raise ValueError(f"{value!r}: not a finite JSON value ({e})") from None


def is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def finite_or_nan(x: Any) -> float:
    return math.nan if x is None else float(x)
