"""The calibrated closures the ``python`` and ``c`` exports carry, read from the package
data and the refit files into the types of :mod:`wetcontact.export.closure_tables`.

Six functions (and the division and dynamic rupture closures, :mod:`.transfer_fraction`,
:mod:`.dynamic_rupture`), SI units, force on the first particle along the line of centres,
positive = pushing apart (a bridge's attraction is negative), ``r2 = inf`` for a plane:

``viscous_force_immersed(r1, r2, viscosity, approach_speed, gap)``
    ``calibrated-viscous`` (immersed): ``F = 6 pi eta R v lambda`` (wall) or
    ``6 pi eta R (v/2) lambda`` (equal spheres, v the relative approach speed), lambda a
    Chebyshev table in ln(S/R) (Brenner 1961; Maude 1961; held-out error about 5e-9), S/R
    in [1e-5, 100].
``viscous_force_bridge(r1, r2, viscosity, volume, approach_speed, gap)``
    ``calibrated-viscous`` (bridge): the Reynolds force times the refitted finite-liquid
    factor (held-out error 0.2-0.3 % against ``lubrication``). Domain: V/r_small^3 in
    [1e-4, 0.1], S/H in [0.01, 0.95], radius ratio 1-10; below S/H = 0.01 the near-contact
    branch of :func:`~wetcontact.reduced_models.calibrated.bridge_force`.
``rupture_distance(r1, r2, volume, theta1_deg, theta2_deg)``
    ``calibrated-capillary``: ``S_c = R_s v^(1/3) exp(sum C T_i(w) T_j(a) T_k(b))``, a tensor
    Chebyshev interpolant of ``meniscus``. Domain: a plane or a sphere pair with
    ``r = R_l/R_s`` in [1, 10], ``v = V/R_s^3`` in [1e-4, 0.1], contact angles in [0, 70]
    deg: one angle, or two where the package data has the two-angle table (a plane:
    ``sphere-wall-two-angles``; two spheres: ``sphere-sphere-two-angles``), carried in bands
    of the sphere's angle split along the ridge theta2* of S_c.
``capillary_force(r1, r2, volume, gap, surface_tension, theta1_deg, theta2_deg)``
    ``calibrated-capillary``: ``F = -2 pi sigma R* (2 cos theta) exp(sum C T_i(w) T_j(a)
    T_k(b) T_l(c))`` (two angles: ``cos theta1 + cos theta2``), c the gap coordinate
    (:func:`~wetcontact.reduced_models.calibrated_capillary.gap_coordinate`); same domain,
    any gap ``S >= 0``, exactly 0 at and past ``S_c``.
``rupture_distance_refit``, ``capillary_force_refit`` (same arguments)
    Refitted ``lian-rupture`` (Lian 1993), ``willett`` (Willett 2000): equal spheres, V* in
    [1e-4, 0.1], angles' cosine mean in [0, 50] deg.

:class:`~wetcontact.export.closure_tables.CapillarySource` (:func:`capillary_source`) is the
one place that names the capillary tables the exports carry (pieces, bands, ridge and onset
series, tensor trains where a piece has them). Outside the calibrated domain every function
returns NaN; the package raises :class:`~wetcontact.errors.ValidityError` there (NaN in
:func:`~wetcontact.export.package_evaluation.package_evaluation`). How the exports carry
the tables: the guide's record *Export tables* (``docs/export.md``).
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.export.closure_tables import (
    KINDS,
    PAIR_TWO_ANGLES,
    TWO_ANGLE_KINDS,
    CapillaryBand,
    CapillaryPart,
    CapillaryPiece,
    CapillarySource,
    CapillaryTable,
    RefitTable,
    TensorTrain,
    sphere_end_text,
)

#: the refitted calibration JSONs the exports carry by default, shipped as package data
#: (copies of ``benchmarks/results/calibration/{willett,lian-rupture}.json``, written by
#: ``wetcontact calibrate``; ``tests/test_export_closures.py`` keeps them equal), so that
#: ``export python`` and ``export c`` work from an installed package, not only a checkout
REFIT_DIR = Path(__file__).resolve().parents[1] / "reduced_models" / "data"
REFIT_FILES = {"willett": "refit_willett.json", "lian-rupture": "refit_lian-rupture.json"}


USAGE = """\
FOR A DEM CONTACT LAW (the figures below are measured against the package's own models):
- Arguments: r1 is the particle the force acts on, r2 the other (INF for a plane: the
  plane is always r2; r1 = INF returns NAN). Each contact angle goes with its own radius
  (theta1 with r1, theta2 with r2); on a plane theta1 is the sphere's. Between spheres the
  functions are symmetric in (r1, theta1) <-> (r2, theta2).
- approach_speed v = -d(gap)/dt: positive on approach, negative on separation (the
  viscous forces are odd in v: the same magnitude, pulling, on separation; no cavitation).
- Past the rupture distance S_c there is no bridge: gate the bridge viscous force with
  rupture_distance (it can be finite there for large bridges, from its S/H domain alone);
  the capillary force is exactly 0 there and jumps to 0 at S_c (from 3.7 % of its contact
  value for V/R^3 = 0.01 at 20 deg on a plane). Whether a bridge exists on the way back in
  (it forms only at contact) is the contact law's state to keep.
- Near contact (S/H < x0 = {bh_lo:g}) the bridge viscous force is its near-contact
  branch 6 pi eta R*^2 v/S (1 - S/H)^2 (1 + rho S/(x0 H)), rho = phi(x0)/(1 - x0)^2 - 1
  from the fitted factor phi at S/H = x0 (continuous there): it tends to Reynolds'
  6 pi eta R*^2 v/S as S/H -> 0, as `lubrication` does, and is within 0.3 % of
  `lubrication` for S/H in [1e-3, x0] (V/r_small^3 <= 0.1, radius ratio 1-10); S = 0
  gives NAN. Just before rupture (S/H > {bh_hi:g}) it gives NAN: there Pitois et al.
  (2000)'s 6 pi eta R*^2 v/S (1 - S/H)^2 is within 0.16 % of `lubrication`.
- Overlap (gap < 0) gives NAN: clamp the gap to your contact model's minimum.
- Every function is re-entrant (no mutable static state): call it from any thread."""
"""Usage notes common to the C header and the numpy module (plain text; ``{bh_lo}`` and
``{bh_hi}`` are the bridge viscous domain's S/H ends)."""

USAGE_C_CONTACT = """\
- A capillary contact whose volume, radii, angles and surface tension stay fixed: set up
  once with wc_capillary_contact_init, then wc_capillary_force_at(&contact, gap) per step
  (gcc 12 -O2, one 2.1 GHz Xeon core: 0.08 us a call, against 1.7-1.8 us on a plane and
  5.5-7.3 us between spheres for wc_capillary_force)."""
"""The C header's per-contact calls (the numpy module evaluates whole arrays instead)."""


def usage_text(bh_lo: float, bh_hi: float, lang: str) -> str:
    """:data:`USAGE` for the C header (``lang="c"``: ``wc_`` names, INFINITY, NAN) or the
    numpy module (``"python"``: numpy.inf, NaN), plain lines (no comment prefix)."""
    text = USAGE.format(bh_lo=bh_lo, bh_hi=bh_hi)
    if lang == "c":
        text = re.sub(r"\b(capillary_force|rupture_distance)\b", r"wc_\1",
                      text).replace("INF", "INFINITY") + "\n" + USAGE_C_CONTACT
    else:
        text = text.replace("INF", "numpy.inf").replace("NAN", "NaN")
    head, *items = re.split(r"\n(?=- )", text)  # the heading, then one item per bullet
    return "\n".join([head] + [textwrap.fill(" ".join(item.split()), width=86,
                                              subsequent_indent="  ") for item in items])


LAYOUT_HINT = "the layout written by python -m wetcontact.generate calibrated-capillary"


def _capillary_part(path: Path, kind: str, e: dict[str, Any]) -> CapillaryPart:
    """One geometry's entry, the layout the model
    (:func:`~wetcontact.reduced_models.calibrated_capillary.force_star`) reads.

    One angle: ``pieces`` (and ``theta_split``), rupture tables 2-D (a wall) or 3-D (sphere
    pairs), a 1-D split series, the pieces contiguous from 0 to 70 deg.

    Two angles on a wall: ``bands``, each with its ``theta_sphere_deg`` range (finite, or
    ``None`` for the onset angle of the entry's ``theta_sphere_split``, a non-empty 1-D
    Chebyshev series in ``a`` of finite numbers; increasing at every ``a`` in [-1, 1]; the
    bands contiguous from 0 to 70 deg, an end ``None`` followed by a start ``None``), a
    2-D ridge series over (a, b1) and pieces of rupture tables 3-D (a, b1, b2), contiguous
    from 0 deg to an end at or above 70 deg (past the domain: the ridge may lie above 70
    deg). An entry with the former top-level ``pieces``/``theta_split`` (one table over the
    whole sphere range) is refused: the model no longer evaluates it.

    Two angles between spheres (``sphere-sphere-two-angles``): the same with the lead
    coordinates (w, a) where the wall's are (a): the onset series 2-D over (w, a) (the
    bands' ends compared on a grid of both), ridge series 3-D over (w, a, b1), rupture
    tables 4-D (w, a, b1, b2); the last piece of a band may carry ``upper_past_ridge``
    (its lower end the ridge, its upper end a number plus the ridge's offset from theta1:
    :func:`_moving_top`, at or above 70 deg on a grid of (w, a, b1))."""
    from wetcontact.reduced_models.calibrated_capillary import (
        ONSET_KEY,
        THETA_RANGE_DEG,
        chebyshev_tensor,
    )

    strata = {k.removeprefix("held_out_"): v for k, v in e.items()
              if k.startswith("held_out_") and isinstance(v, dict)}
    if kind not in TWO_ANGLE_KINDS:
        pieces, split = _sections(path, kind, kind, e)
        return CapillaryPart(kind, pieces, split, e.get("held_out", {}), strata)
    pair = kind == PAIR_TWO_ANGLES
    raw = e.get("bands")
    allowed = ("allowed: 'bands', a list of tables each with 'theta_sphere_deg' [lo, hi] "
               f"(finite, or null for the onset angle of the field {ONSET_KEY!r}; "
               f"increasing, contiguous from {THETA_RANGE_DEG[0]:g} to "
               f"{THETA_RANGE_DEG[1]:g} deg), 'theta_split' (a "
               + ("3-D Chebyshev series in (w, a, b1)" if pair else
                  "2-D Chebyshev series in (a, b1)")
               + ") and 'pieces' (" + LAYOUT_HINT + ")")
    if "pieces" in e or "theta_split" in e:
        raise InputError(f"{path}: {kind}: top-level fields 'pieces'/'theta_split' (one "
                         "table over the whole sphere angle range, a layout the model no "
                         f"longer evaluates); {allowed}")
    if not isinstance(raw, list) or not raw:
        raise InputError(f"{path}: {kind}: field 'bands' = {raw!r}; {allowed}")
    _no_ridge_margin(path, kind, e)
    onset = _onset_series(path, kind, e.get(ONSET_KEY))
    # the onset angle at Chebyshev-Lobatto points of a (a pair: of w and a), summed as the
    # model sums it: where the bands' ends are compared
    grid = [np.cos(np.linspace(0.0, math.pi, 513))]
    if pair:
        w, a = np.meshgrid(*[np.cos(np.linspace(0.0, math.pi, 65))] * 2, indexing="ij")
        grid = [w.ravel(), a.ravel()]
    on = None if onset is None else chebyshev_tensor(onset, grid)
    bands: list[CapillaryBand] = []
    top: float | None = THETA_RANGE_DEG[0]
    for i, h in enumerate(raw):
        where = f"{kind} band {i}"
        rng = h.get("theta_sphere_deg") if isinstance(h, dict) else None
        try:
            lo, hi = (None if x is None else float(x) for x in rng)
        except (TypeError, ValueError):
            raise InputError(f"{path}: {where}: theta_sphere_deg = {rng!r}; {allowed}"
                             ) from None
        if None in (lo, hi) and on is None:
            raise InputError(f"{path}: {where}: theta_sphere_deg = {rng!r}, an end null (the "
                             f"onset angle) in an entry without the field {ONSET_KEY!r}; "
                             f"{allowed}")
        if not all(x is None or math.isfinite(x) for x in (lo, hi)) or lo != top:
            raise InputError(f"{path}: {where}: theta_sphere_deg = {rng!r} (after "
                             f"{sphere_end_text(top)} deg); {allowed}")
        ends = [on if x is None else x for x in (lo, hi)]
        if not np.all(np.less(*ends)):
            raise InputError(
                f"{path}: {where}: theta_sphere_deg = {rng!r}, empty or decreasing"
                + ("" if on is None else f" where the onset angle is {np.min(on):.6g} to "
                   f"{np.max(on):.6g} deg (a in [-1, 1])") + f"; {allowed}")
        top = hi
        pieces, split = _sections(path, kind, where, h)
        if split is None:
            raise InputError(f"{path}: {where}: field 'theta_split' missing; {allowed}")
        band = CapillaryBand(lo, hi, pieces, split)
        if pair and pieces[-1].upper_past_ridge:
            _moving_top(path, where, band, onset)
        bands.append(band)
    if top != THETA_RANGE_DEG[1]:
        ends = [[hv.theta_sphere_lo, hv.theta_sphere_hi] for hv in bands]
        raise InputError(f"{path}: {kind}: bands' theta_sphere_deg {ends} end at "
                         f"{sphere_end_text(top)} deg; {allowed}")
    return CapillaryPart(kind, (), None, e.get("held_out", {}), strata, tuple(bands), onset)


def _onset_series(path: Path, kind: str, raw: Any) -> np.ndarray | None:
    """The two-angle entry's onset series (``theta_sphere_split``: ``{"chebyshev": [o_0,
    ...]}`` on a wall, ``{"chebyshev": [[o_00, ...], ...]}`` (rows in w) for a pair, deg),
    validated; ``None`` when absent."""
    from wetcontact.reduced_models.calibrated_capillary import ONSET_KEY

    if raw is None:
        return None
    coef = raw.get("chebyshev") if isinstance(raw, dict) else None
    pair = kind == PAIR_TWO_ANGLES

    def numbers(x: Any) -> bool:
        return isinstance(x, list) and bool(x) and all(
            isinstance(c, int | float) and not isinstance(c, bool) and math.isfinite(c)
            for c in x)

    good = (isinstance(coef, list) and bool(coef) and all(numbers(row) for row in coef)
            and len({len(row) for row in coef}) == 1) if pair else numbers(coef)
    if not good:
        raise InputError(
            f"{path}: {kind}: field {ONSET_KEY!r} = {raw!r}; allowed: "
            + ("{'chebyshev': [[o_00, ..., o_0n], ...]}, a non-empty rectangular list of "
               "lists of finite numbers (the onset angle theta_on = sum_ij o_ij T_i(w) "
               "T_j(a), deg, a 2-D Chebyshev series in the ratio and volume coordinates)"
               if pair else
               "{'chebyshev': [o_0, ..., o_n]}, a non-empty list of finite numbers "
               "(the onset angle theta_on = sum_k o_k T_k(a), deg, a 1-D Chebyshev "
               "series in the volume coordinate a)"))
    return np.asarray(coef, dtype=float)


MOVING_TOP_GRID = 17
"""Chebyshev-Lobatto points per lead axis and b1 at which :func:`_moving_top` checks a
pair band's moving upper end."""


def _moving_top(path: Path, where: str, band: CapillaryBand,
                onset: np.ndarray | None) -> None:
    """Refuse a pair band whose last piece's moving upper end (``upper_past_ridge``:
    ``hi + theta2* - theta1``) falls below the domain's 70 deg or to the ridge at some point
    of a grid of (w, a, b1) (:data:`MOVING_TOP_GRID` per axis): the model would leave large
    sphere angles there in no piece."""
    from wetcontact.reduced_models.calibrated_capillary import (
        THETA_RANGE_DEG,
        chebyshev_tensor,
    )

    x = np.cos(np.linspace(0.0, math.pi, MOVING_TOP_GRID))
    w, a, b1 = (g.ravel() for g in np.meshgrid(x, x, x, indexing="ij"))
    on = None if onset is None else chebyshev_tensor(onset, [w, a])
    lo, hi = (on if e is None else np.full(w.shape, e)
              for e in (band.theta_sphere_lo, band.theta_sphere_hi))
    t1 = 0.5 * (b1 * (hi - lo) + lo + hi)
    ridge = chebyshev_tensor(band.split, [w, a, b1])
    top = band.pieces[-1].theta_hi + (ridge - t1)
    low = np.minimum(top - THETA_RANGE_DEG[1], top - ridge)
    if not np.all(low > 0.0):
        k = int(np.argmin(low))
        raise InputError(
            f"{path}: {where} piece {len(band.pieces) - 1}: upper_past_ridge end "
            f"{band.pieces[-1].theta_hi:g} + theta2* - theta1 = {top[k]:.6g} deg at (w, a, "
            f"b1) = ({w[k]:.3g}, {a[k]:.3g}, {b1[k]:.3g}), the ridge there {ridge[k]:.6g} "
            f"deg; allowed: above {THETA_RANGE_DEG[1]:g} deg and above the ridge everywhere")


def _sections(path: Path, kind: str, where: str, e: dict[str, Any]
              ) -> tuple[tuple[CapillaryPiece, ...], np.ndarray | None]:
    """The ``pieces`` and ``theta_split`` of one table (a one-angle geometry, or one band
    of a wall with two angles, named ``where`` in the messages), validated."""
    from wetcontact.reduced_models.calibrated_capillary import (
        THETA_RANGE_DEG,
        UPPER_PAST_RIDGE,
    )

    raw = e.get("pieces")
    if not raw:
        raise InputError(f"{path}: {where}: field 'pieces' missing or empty; allowed: "
                         + LAYOUT_HINT)
    two = kind in TWO_ANGLE_KINDS
    pair2 = kind == PAIR_TWO_ANGLES
    ndim = {"sphere-wall": 2, PAIR_TWO_ANGLES: 4}.get(kind, 3)
    pieces = []
    for i, p in enumerate(raw):
        try:
            rup = np.asarray(p["rupture"], dtype=float)
            left = np.asarray(p["force_left"], dtype=float)
            right = np.asarray(p["force_right"], dtype=float)
        except (KeyError, ValueError) as exc:
            raise InputError(f"{path}: {where} piece {i}: fields 'rupture', 'force_left' and "
                             f"'force_right' (numeric arrays) expected ({exc}); allowed: "
                             + LAYOUT_HINT) from None
        if left.ndim < 2 or right.ndim < 2 or left.shape[-1] != right.shape[0]:
            raise InputError(f"{path}: {where} piece {i}: force factors of shapes "
                             f"{left.shape} and {right.shape}; allowed: (..., r) and (r, ...)")
        shape = (*left.shape[:-1], *right.shape[1:])  # the force table's axes
        if rup.ndim != ndim or shape[:-1] != rup.shape or not (
                np.all(np.isfinite(rup)) and np.all(np.isfinite(left))
                and np.all(np.isfinite(right))):
            raise InputError(f"{path}: {where} piece {i}: tables of shapes {rup.shape} "
                             f"(rupture), {left.shape} and {right.shape} (force factors); "
                             f"allowed: finite, rupture {ndim}-D, the force (the factors' "
                             "product) the same plus a gap axis")
        lo, hi = p["theta_deg"]
        tmap = p.get("theta_map", "linear")
        if tmap not in ("linear", "ridge-quadratic") or (
                tmap == "ridge-quadratic" and None not in (lo, hi)):
            raise InputError(f"{path}: {where} piece {i}: theta_map = {tmap!r}; allowed: "
                             "'linear', or 'ridge-quadratic' for a piece that ends at the "
                             "split angle")
        past = p.get(UPPER_PAST_RIDGE, False)
        if past not in (True, False) or (past and not (
                pair2 and i == len(raw) - 1 and lo is None and hi is not None)):
            raise InputError(f"{path}: {where} piece {i}: {UPPER_PAST_RIDGE} = {past!r} "
                             f"(theta_deg {[lo, hi]}); allowed: absent or false, or true on "
                             "a sphere pair's last piece [null, number] (its upper end the "
                             "number plus the ridge's offset from theta1)")
        trains = {name: _train(path, f"{where} piece {i}", name, p[name], axes)
                  for name, axes in (("rupture_train", rup.shape), ("force_train", shape))
                  if name in p}
        pieces.append(CapillaryPiece(None if lo is None else float(lo),
                                     None if hi is None else float(hi), rup, left, right,
                                     tmap == "ridge-quadratic", bool(past), **trains))
    ts = e.get("theta_split")
    split = None if ts is None else np.asarray(ts["chebyshev"], dtype=float)
    bounds = [x for p in pieces for x in (p.theta_lo, p.theta_hi)]
    ends = [(p.theta_lo, p.theta_hi) for p in pieces]
    contiguous = all(p.theta_hi == q.theta_lo for p, q in zip(pieces, pieces[1:], strict=False))
    lo, hi = pieces[0].theta_lo, pieces[-1].theta_hi
    if two:  # the last piece may reach past the domain (the ridge may be above it)
        spans = lo == THETA_RANGE_DEG[0] and hi is not None and hi >= THETA_RANGE_DEG[1]
        top = f"an end at or above {THETA_RANGE_DEG[1]:g}"
    else:
        spans, top = (lo, hi) == tuple(THETA_RANGE_DEG), f"{THETA_RANGE_DEG[1]:g}"
    split_ndim = 3 if pair2 else 2 if two else 1
    if split is not None and (split.ndim != split_ndim or not np.all(np.isfinite(split))):
        raise InputError(f"{path}: {where} theta_split of shape {split.shape}; allowed: a "
                         f"finite {split_ndim}-D Chebyshev series in "
                         + ("(w, a, b1)" if pair2 else "(a, b1)" if two else "a"))
    if (None in bounds and split is None) or not contiguous or not spans:
        raise InputError(f"{path}: {where} theta pieces {ends}; allowed: contiguous from "
                         f"{THETA_RANGE_DEG[0]:g} to {top} deg, None (the split angle) only "
                         "with a theta_split series")
    _no_ridge_margin(path, where, e)
    return tuple(pieces), split


TRAIN_LAYOUT = ("{'order': [o_1, ..., o_d] (a permutation of the table's axes 0..d-1), "
                "'tol': a finite number >= 0 (optional), 'ranks': [r_1, ..., r_(d-1)] "
                "(optional), 'cores': [G_1, ..., G_d], G_k a finite array of shape "
                "(r_(k-1), n_(o_k), r_k), r_0 = r_d = 1, n the table's shape}")
"""How a piece's tensor train is laid out (:class:`TensorTrain`), for the messages."""


def _train(path: Path, where: str, name: str, raw: Any, shape: tuple[int, ...]
           ) -> TensorTrain:
    """A piece's tensor train ``name`` (``rupture_train`` or ``force_train``) of the table
    of shape ``shape``, validated: :data:`TRAIN_LAYOUT`, each core's shape chained to its
    neighbours' ranks and to the table axis it carries; an :class:`InputError` naming the
    file, the piece, the field and its value otherwise."""
    def refuse(what: str) -> InputError:
        return InputError(f"{path}: {where}: field {name!r} {what}; allowed: "
                          f"{TRAIN_LAYOUT} with table shape {shape}")

    if not isinstance(raw, dict) or not {"order", "cores"} <= set(raw):
        keys = sorted(raw) if isinstance(raw, dict) else type(raw).__name__
        raise refuse(f"= {keys!r} (not a dict with 'order' and 'cores')")
    order, d = raw["order"], len(shape)
    if not (isinstance(order, list | tuple) and all(
            isinstance(o, int) and not isinstance(o, bool) for o in order)
            and sorted(order) == list(range(d))):
        raise refuse(f"order = {order!r} (the table has {d} axes)")
    try:
        cores = tuple(np.asarray(g, dtype=float) for g in raw["cores"])
    except (TypeError, ValueError) as exc:
        raise refuse(f"cores not numeric arrays ({exc})") from None
    shapes = [g.shape for g in cores]
    if len(cores) != d:
        raise refuse(f"has {len(cores)} cores of shapes {shapes}; want {d}, one per axis")
    ranks = [1] + [g.shape[-1] if g.ndim == 3 else -1 for g in cores[:-1]] + [1]
    want = [(ranks[k], shape[o], ranks[k + 1]) for k, o in enumerate(order)]
    if shapes != want:
        raise refuse(f"cores of shapes {shapes} (order {list(order)}); want {want}")
    if not all(np.all(np.isfinite(g)) for g in cores):
        raise refuse("cores not finite")
    if "ranks" in raw and not (isinstance(raw["ranks"], list | tuple)
                               and list(raw["ranks"]) == ranks[1:-1]):
        raise refuse(f"ranks = {raw['ranks']!r}, the cores' {ranks[1:-1]}")
    tol = raw.get("tol")
    if tol is not None and not (isinstance(tol, int | float) and not isinstance(tol, bool)
                                and math.isfinite(tol) and tol >= 0):
        raise refuse(f"tol = {tol!r}")
    return TensorTrain(tuple(order), cores, None if tol is None else float(tol))


def _no_ridge_margin(path: Path, where: str, e: dict[str, Any]) -> None:
    """Refuse a table (or a two-angle entry) carrying a ridge margin: a layout from before
    the quadratic ridge map, when pieces were continued past the ridge."""
    if e.get("ridge_margin_deg", 0.0) != 0.0:
        raise InputError(f"{path}: {where} ridge_margin_deg = {e['ridge_margin_deg']!r}; "
                         "allowed: 0 or absent (each point is evaluated in its own piece, "
                         "as the model does)")


def shipped_capillary() -> CapillaryTable:
    """The package's ``calibrated-capillary`` table; an :class:`InputError` before it is
    generated. Geometries, theta pieces and shapes are read from the data, never assumed."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    table = cc.capillary_table()
    path = Path(__file__).resolve().parents[1] / "reduced_models" / "data" / cc.CAPILLARY_FILE
    if table is None or not path.is_file():
        raise InputError("calibrated-capillary: coefficient table not generated; run "
                         "`python -m wetcontact.generate calibrated-capillary`")
    parts = {kind: _capillary_part(path, kind, table[kind]) for kind in KINDS if kind in table}
    for key, want in (("v", cc.V_RANGE), ("theta_deg", cc.THETA_RANGE_DEG),
                      ("radius_ratio", cc.RATIO_RANGE)):
        if tuple(table["domain"][key]) != tuple(want):
            raise InputError(f"{path}: domain.{key} = {table['domain'][key]}; allowed: "
                             f"{list(want)} (the model's range)")
    return CapillaryTable(parts, cc.V_RANGE, cc.THETA_RANGE_DEG, cc.RATIO_RANGE,
                          cc.ANGLE_TOL, cc.W_MAX, str(path),
                          hashlib.sha256(path.read_bytes()).hexdigest())


def read_refit(path: Path | str, family: str | None = None) -> RefitTable:
    """A refitted family from ``path`` (``family``: the one it must be; None: any); an
    :class:`InputError` naming the file otherwise."""
    from wetcontact.calibrate import load_coefficients

    path = Path(path)
    if not path.exists():  # a FIFO or a folder is refused by load_coefficients, by name
        raise InputError(f"{path}: no such calibration file; write it with `python -m "
                         f"wetcontact.generate fit {family or 'FAMILY'} --out {path}` or name "
                         "another with " + ("--capillary / --rupture" if family else "--refit"))
    closure = load_coefficients(path)  # validates family, size and finiteness
    family = family or closure.family.name
    if closure.family.name != family:
        raise InputError(f"{path}: family = {closure.family.name!r}; allowed: {family!r} "
                         "(the only family this export writes for that function)")
    data = json.loads(path.read_text())
    ho = data.get("held_out", {}).get("after", {})
    if not isinstance(ho.get("max"), int | float):
        raise InputError(f"{path}: field 'held_out.after.max' missing; allowed: a file "
                         "written by wetcontact calibrate")
    return RefitTable(family, tuple(float(c) for c in closure.k), dict(closure.domain),
                      float(ho["max"]), int(data["held_out"].get("points", 0)), str(path),
                      hashlib.sha256(path.read_bytes()).hexdigest())


def capillary_source(force: Path | str | None = None,
                     rupture: Path | str | None = None) -> CapillarySource:
    """The shipped ``calibrated-capillary`` table and the refitted pair from the given files
    (default: the package's shipped refits)."""
    return CapillarySource(
        shipped_capillary(),
        read_refit(force or REFIT_DIR / REFIT_FILES["willett"], "willett"),
        read_refit(rupture or REFIT_DIR / REFIT_FILES["lian-rupture"], "lian-rupture"))


def immersed_tables() -> dict[str, Any]:
    """The shipped ``calibrated-viscous`` immersed tables (sphere-wall, sphere-sphere)."""
    from wetcontact.reduced_models.calibrated import viscous_table

    table = viscous_table()
    if table is None:
        raise InputError("calibrated-viscous: coefficient table not generated; run "
                         "`python -m wetcontact.generate calibrated-viscous`")
    return table["immersed"]
