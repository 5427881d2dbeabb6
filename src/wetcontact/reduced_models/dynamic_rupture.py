r"""Dynamic rupture distance: the static fold stretched by the capillary number.

A bridge separated at the constant relative speed v ruptures farther out than its static
fold S_c (the last stable static bridge, ``meniscus``). The closure is fitted to the
``stokes-dynamic`` reference (free-surface Stokes flow to the pinch,
:mod:`wetcontact.solver.stokes_dynamic.rupture`):

.. math::
    \frac{S_c(\mathrm{Ca})}{S_c} = 1 + a_k\, \mathrm{Ca}^{\,b_k + c_k \ln \mathrm{Ca}}
        \left(\frac{V^*}{10^{-3}}\right)^{d_k} e^{e_k \theta} \rho^{g_k},
    \qquad \mathrm{Ca} = \eta v / \sigma,

with one set ``(a, b, c, d, e, g)`` per geometry ``k`` (a sphere and a wall; two spheres),
theta in rad (static, equal on both solids). On a wall ``V* = V/R^3`` and ``rho = 1``;
between spheres R1 and R2, ``V* = V/R*^3`` with Derjaguin's ``R* = 2 R1 R2/(R1 + R2)``
(:func:`effective_radius`) and ``rho = min(R1, R2)/max(R1, R2)`` (equal spheres: ``V/R^3``
and 1). With ``c = d = e = g = 0`` it is Pitois, Moucheront & Chateau's (2001) form, whose
published ``a = 1, b = 1/2``
(:func:`~wetcontact.reduced_models.rupture.pitois_rupture_distance`) the report compares.

Domain: Ca, V*, theta and rho within the generation grid (``domain`` in the package data,
``data/dynamic_rupture.json``, built by ``python -m wetcontact.generate dynamic-rupture``);
the bridge starts from the static meniscus at 0.2 S_c. Between equal spheres the angle is at
most 30 deg (:data:`wetcontact.solver.stokes_dynamic.rupture.PAIR_THETA_MAX`: above about
33 deg the static branch ends at a symmetry-breaking bifurcation before its fold, which the
reference, solved on the symmetric half, cannot follow).

Accuracy: relative error of ``S_c(Ca)`` on the 16 held-out runs of the data file
(``held_out``; the report's ``dynamic_rupture.csv``): max 7.4 %, mean 2.2 % (Pitois' factor:
11 %, 6.2 %); by geometry, on a wall 6.4 %, between equal spheres 5.9 %, between unequal
ones (rho 0.48-0.71) 7.4 % (mean 3.3 %). On the 105 grid runs max 20 %, at Ca = 0.3 between
spheres R and 4R at 10 deg: the excess grows as rho falls at Ca <= 1e-2 but hardly
depends on rho at Ca = 0.3, which one power ``rho^g`` cannot follow (a term
``ln rho ln Ca`` brings the grid to 6.6 % but not the held-out runs below 7.4 %). The
reference's own time error is a few tenths of a percent
(:mod:`wetcontact.solver.stokes_dynamic.rupture`).
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.reduced_models import DATA_DIR

__all__ = ["dynamic_rupture_ratio", "fit_form", "ratio_form", "DATA_FILE", "SCHEMA_VERSION"]

DATA_FILE = "dynamic_rupture.json"
SCHEMA_VERSION = 2
NAMES = ("a", "b", "c", "d", "e", "g")


def effective_radius(radius_ratio: Any) -> Any:
    """``R*/R = 2 R2 / (R + R2)`` of spheres R and ``radius_ratio`` R (the harmonic mean of
    the radii, Derjaguin's; R for equal spheres)."""
    q = np.asarray(radius_ratio, dtype=float)
    return 2.0 * q / (1.0 + q)


def ratio_form(coef: dict[str, Any], wall: Any, ca: Any, volume: Any, theta_deg: Any,
               rho: Any = 1.0) -> np.ndarray:
    """``S_c(Ca)/S_c`` of the form above with coefficients ``coef[kind][name]``
    (``volume`` is V*, ``rho`` the radius ratio <= 1)."""
    wall, ca, v, th, q = np.broadcast_arrays(
        np.asarray(wall, dtype=bool), np.asarray(ca, float), np.asarray(volume, float),
        np.radians(np.asarray(theta_deg, float)), np.asarray(rho, float))
    out = np.empty(ca.shape)
    for kind, sel in (("wall", wall), ("pair", ~wall)):
        if not sel.any():
            continue
        a, b, c, d, e, g = (float(coef[kind].get(n, 0.0)) for n in NAMES)
        lc = np.log(ca[sel])
        out[sel] = 1.0 + a * np.exp((b + c * lc) * lc + d * np.log(v[sel] / 1e-3)
                                    + e * th[sel] + g * np.log(q[sel]))
    return out


def pair_coordinates(volume_star: Any, radius_ratio: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(V/R*^3, rho)`` of spheres R and ``radius_ratio`` R holding ``volume_star`` R^3."""
    q = np.asarray(radius_ratio, dtype=float)
    return (np.asarray(volume_star, float) / effective_radius(q) ** 3,
            np.minimum(q, 1.0 / q))


def fit_form(wall: np.ndarray, ca: np.ndarray, volume: np.ndarray, theta_deg: np.ndarray,
             ratio: np.ndarray, names: tuple[str, ...] = NAMES, rho: np.ndarray | None = None
             ) -> dict[str, dict[str, float]]:
    """Least-squares fit of the form to reference ratios, per kind, in
    ``ln(ratio - 1) = ln a + (b + c ln Ca) ln Ca + d ln(V*/1e-3) + e theta + g ln rho``
    (linear in the coefficients; ``volume`` is V*, ``rho`` the radius ratios, default 1);
    coefficients not in ``names`` are 0, and ``g`` is fitted only where rho varies."""
    out: dict[str, dict[str, float]] = {}
    lq_all = np.zeros(ca.shape) if rho is None else np.log(rho)
    for kind, sel in (("wall", wall), ("pair", ~wall)):
        lc, lv = np.log(ca[sel]), np.log(volume[sel] / 1e-3)
        th = np.radians(theta_deg[sel])
        y = np.log(ratio[sel] - 1.0)
        cols = {"a": np.ones_like(lc), "b": lc, "c": lc * lc, "d": lv, "e": th,
                "g": lq_all[sel]}
        use = [n for n in NAMES if n in names and (n != "g" or np.ptp(cols["g"]) > 0)]
        m = np.column_stack([cols[n] for n in use])
        sol, *_ = np.linalg.lstsq(m, y, rcond=None)
        got = dict(zip(use, sol, strict=True))
        coef = {n: float(got.get(n, 0.0)) for n in NAMES}
        coef["a"] = math.exp(coef["a"])
        out[kind] = coef
    return out


@lru_cache(maxsize=1)
def load() -> dict[str, Any]:
    """The shipped coefficients and domain."""
    path = DATA_DIR / DATA_FILE
    if not path.is_file():
        raise InputError(f"dynamic rupture closure: {path} is missing; build it with "
                         "`python -m wetcontact.generate dynamic-rupture`")
    data = json.loads(path.read_text())
    if data.get("schema_version") != SCHEMA_VERSION:
        raise InputError(f"{path}: schema_version {data.get('schema_version')}; this code "
                         f"reads {SCHEMA_VERSION}")
    return data


def dynamic_rupture_ratio(kind: str, capillary_number: Any, volume_star: Any,
                          theta_deg: Any, radius_ratio: Any = 1.0) -> Any:
    r"""``S_c(Ca) / S_c``: the dynamic rupture distance over the static fold.

    .. math:: S_c(\mathrm{Ca})/S_c = 1 + a\, \mathrm{Ca}^{b + c \ln \mathrm{Ca}}
              (V^*/10^{-3})^d e^{e\theta} \rho^g

    (module docstring: the form, the reference, the source).

    Parameters
    ----------
    kind
        ``"wall"`` (a sphere and a wall) or ``"pair"`` (two spheres).
    capillary_number
        ``Ca = eta v / sigma`` with v the relative separation speed.
    volume_star
        ``V/R^3``, R the (first) sphere's radius.
    theta_deg
        Contact angle (deg), the same on both solids (the domain's range for ``kind``).
    radius_ratio
        ``R2/R`` of the second sphere of a pair (1 on a wall).

    Returns
    -------
    numpy.ndarray or float
        The ratio (a float for scalar inputs).

    Raises
    ------
    InputError
        An unknown kind, or an input outside the fitted domain (named with its range; use
        ``stokes-dynamic`` there).
    """
    data = load()
    if kind not in ("wall", "pair"):
        raise InputError(f"dynamic rupture closure: kind = {kind!r}; allowed: 'wall', 'pair'")
    dom = data["domain"]
    q = np.asarray(radius_ratio, float)
    if kind == "wall" and np.any(q != 1.0):
        raise InputError(f"dynamic rupture closure: radius_ratio = "
                         f"{float(q[q != 1.0].flat[0]):.6g} on a wall; allowed: 1")
    if np.any(~np.isfinite(q)) or np.any(q <= 0):
        raise InputError(f"dynamic rupture closure: radius_ratio = {q.min():.6g}-"
                         f"{q.max():.6g}; allowed: finite > 0")
    v, rho = (np.asarray(volume_star, float), np.ones(q.shape)) if kind == "wall" else (
        pair_coordinates(volume_star, q))
    vals = {"capillary_number": np.asarray(capillary_number, float),
            "volume": v, "theta_deg": np.asarray(theta_deg, float), "rho": rho}
    for name, x in vals.items():
        lo, hi = dom[name][kind] if name == "theta_deg" else dom[name]
        if np.any(~np.isfinite(x)) or np.any(x < lo * (1 - 1e-12)) or np.any(x > hi * (1 + 1e-12)):
            what = {"volume": "V/R*^3" if kind == "pair" else "V/R^3",
                    "rho": "rho = min(1, radius_ratio)/max(1, radius_ratio)"}.get(name, name)
            raise InputError(f"dynamic rupture closure: {what} = {x.min():.6g}-{x.max():.6g} "
                             f"outside [{lo:g}, {hi:g}]; use stokes-dynamic there")
    r = ratio_form(data["coefficients"], kind == "wall", vals["capillary_number"],
                   vals["volume"], vals["theta_deg"], vals["rho"])
    return float(r) if r.ndim == 0 else r
