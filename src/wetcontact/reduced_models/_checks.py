"""Input checks shared by the closures: each returns a float array or raises an
:class:`~wetcontact.errors.InputError` naming the argument, its value and the allowed range."""

from __future__ import annotations

from typing import Any

import numpy as np

from wetcontact.errors import InputError


def positive(name: str, value: Any, unit: str = "") -> np.ndarray:
    """``value`` as floats, each finite and > 0."""
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise InputError(f"{name} = {_shown(value)}; allowed: finite values > 0 {unit}".rstrip())
    return arr


def non_negative(name: str, value: Any, unit: str = "") -> np.ndarray:
    """``value`` as floats, each finite and >= 0."""
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0.0):
        raise InputError(f"{name} = {_shown(value)}; allowed: finite values >= 0 {unit}"
                         .rstrip())
    return arr


def gap(value: Any) -> np.ndarray:
    """A surface gap in m: ``value`` as floats, each finite and >= 0."""
    return non_negative("gap", value, "m")


def angle(name: str, value: Any, hi: float = np.pi) -> np.ndarray:
    """A contact angle in radians, each in [0, hi)."""
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0.0) or np.any(arr >= hi):
        raise InputError(f"{name} = {_shown(value)} rad; allowed: [0, {hi:.6g}) rad")
    return arr


def _shown(value: Any) -> str:
    """The offending value, shortened for arrays."""
    arr = np.ravel(np.asarray(value, dtype=object))
    return repr(value) if arr.size <= 4 else f"array of {arr.size}, e.g. {arr[:3].tolist()}"
