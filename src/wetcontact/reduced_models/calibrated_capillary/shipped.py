"""The shipped calibrated capillary table (package data, :func:`capillary_table`) and the
package's calls of the standalone kernel on it: :func:`force_star`, :func:`rupture_star`,
:func:`ridge_deg`. Here, not in :mod:`.kernel`, because they read package data and raise
the package's errors (:class:`~wetcontact.errors.ValidityError` where no table was
generated, :class:`~wetcontact.errors.InputError` for an unknown precision), which the
kernel, shipped verbatim in the exported numpy module, must not import.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.reduced_models.calibrated_capillary.coordinates import (
    PAIR_TWO_ANGLES,
    WALL_TWO_ANGLES,
    Lead,
    _take,
    ratio_coordinate,
    volume_coordinate,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    PRECISIONS,
    _by_band,
    as_arrays,
    table_star,
    theta_split_deg,
)

CAPILLARY_FILE = "calibrated_capillary.json"


@cache
def capillary_table() -> dict[str, Any] | None:
    """The shipped table, or ``None`` before ``python -m wetcontact.generate
    calibrated-capillary``."""
    path = resources.files("wetcontact.reduced_models") / "data" / CAPILLARY_FILE
    return as_arrays(json.loads(path.read_text())) if path.is_file() else None


def _entry(kind: str) -> dict[str, Any]:
    table = capillary_table()
    if table is None or kind not in table:
        raise ValidityError("calibrated-capillary", f"no {kind} coefficient table generated "
                            "(python -m wetcontact.generate calibrated-capillary)",
                            "meniscus")
    return table[kind]


def force_star(kind: str, v: np.ndarray, theta: np.ndarray, s: np.ndarray,
               ratio: np.ndarray | None = None, chunk: int | None = None,
               entry: dict[str, Any] | None = None, theta_wall: np.ndarray | None = None,
               precision: str = "mixed") -> tuple[np.ndarray, np.ndarray]:
    """Attractive force ``F/(2 pi sigma R_s)`` at gap ``s = S/R_s`` (0 at and beyond
    rupture) and the rupture distance ``S_c/R_s`` from the shipped table: the kernel's
    :func:`~wetcontact.reduced_models.calibrated_capillary.kernel.table_star` (arguments
    and evaluation there; ``entry`` default: the shipped table of ``kind``), after checking
    ``precision`` (:data:`PRECISIONS`); a :class:`~wetcontact.errors.ValidityError` where
    a table it needs was not generated."""
    if precision not in PRECISIONS:
        raise InputError(f"calibrated-capillary: precision = {precision!r}; allowed: "
                         + ", ".join(PRECISIONS))
    return table_star(_entry, kind, v, theta, s, ratio, chunk, entry, theta_wall, precision)


def rupture_star(kind: str, v: np.ndarray, theta: np.ndarray,
                 ratio: np.ndarray | None = None, theta_wall: np.ndarray | None = None
                 ) -> np.ndarray:
    """Rupture distance S_c/R_s (``theta_wall``: the wall's own angle, see
    :func:`force_star`; in double precision whatever its ``precision``)."""
    v = np.asarray(v, dtype=float)
    return force_star(kind, v, theta, np.zeros(v.shape), ratio, theta_wall=theta_wall)[1]


def ridge_deg(v: Any, theta_sphere_deg: Any, entry: dict[str, Any] | None = None,
              ratio: Any = None) -> np.ndarray:
    """The other solid's angle (deg) at the ridge of S_c with two angles, at ``v`` and the
    (small) sphere's angle (deg): the split series of the two-angle table's band that holds
    the sphere's angle (``entry``: that table, default the shipped one: the wall's, or,
    given the radius ratio ``ratio``, the sphere pairs')."""
    if entry is None:
        entry = _entry(WALL_TWO_ANGLES if ratio is None else PAIR_TWO_ANGLES)
    v, t, r = np.broadcast_arrays(np.asarray(v, dtype=float),
                                  np.asarray(theta_sphere_deg, dtype=float),
                                  np.asarray(1.0 if ratio is None else ratio, dtype=float))
    a, out = volume_coordinate(v.ravel()), np.full(v.size, np.nan)
    lead: Lead = a if ratio is None else [ratio_coordinate(r.ravel()), a]
    for band, m, b1 in _by_band(entry, t.ravel(), lead):
        out[m] = theta_split_deg(band, _take(lead, m), b1)
    return out.reshape(v.shape)
