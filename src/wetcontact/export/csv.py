"""``wetcontact export csv``: a study's stored curves as one flat CSV table.

One row per (point, model, gap). Columns: one per study axis, named by its field path
(e.g. ``liquid.contact_angle``, in the units of the study file), then ``model``, ``gap``
(m), ``force_viscous``, ``force_capillary``, ``force_total`` (N, positive = pushing the
surfaces apart), ``status`` and ``reason``. A component the model does not compute is an
empty cell, not zero. ``status`` is ``ok``; ``no-bridge`` at a gap past the bridge's
rupture (force 0 by definition; for a closure, its own rupture distance); ``failed`` (the
model failed or refused the point: ``reason`` says why; forces empty); or ``missing`` (not
in the store: run
``wetcontact sweep`` first). Numbers are written at full precision (shortest repr that
reads back to the same double).

A collision study (:mod:`wetcontact.study`, a collision base) has one row per (point, force
set) instead: the axes, then ``force_set``, ``restitution``, ``outcome`` (``rebound`` or
``stick``), ``stokes_number``, ``contact_velocity`` and ``rebound_velocity`` (m/s),
``transfer_fraction`` (the liquid left on body 1 after rupture), ``bridge_volume`` (m^3),
the viscous and capillary models used, ``status`` (``ok``, ``failed``, ``missing``) and
``reason`` (:data:`COLLISION_COLUMNS`).
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from wetcontact.fileio import atomic_open
from wetcontact.models import ForceCurve
from wetcontact.store import Store
from wetcontact.sweep import Point

FIXED_COLUMNS = ("model", "gap", "force_viscous", "force_capillary", "force_total",
                 "status", "reason")
COLLISION_COLUMNS = ("force_set", "restitution", "outcome", "stokes_number",
                     "contact_velocity", "rebound_velocity", "transfer_fraction",
                     "bridge_volume", "viscous_model", "capillary_model", "status", "reason")


def _cell(x: float | None) -> str:
    return "" if x is None else repr(float(x))


def write_csv(points: Sequence[Point], axes: Sequence[str], store: Store,
              out: str | Path) -> dict[str, int]:
    """Write the rows of ``points`` from ``store`` to ``out`` (atomically).

    Returns
    -------
    dict
        Row counts by status (``ok``, ``no-bridge``, ``failed``, ``missing``) and ``rows``.
    """
    keys = [p.key for p in points]
    curves = store.load_many(set(keys))
    failures = store.failures()
    counts = {"ok": 0, "no-bridge": 0, "failed": 0, "missing": 0, "rows": 0}
    if any(p.collision is not None for p in points):  # one row per impact
        columns, rows_of = COLLISION_COLUMNS, _collision_rows

        def blank(p: Point) -> list[list[str]]:
            return [[""] * (len(COLLISION_COLUMNS) - 3)]
    else:  # one row per gap
        columns, rows_of = FIXED_COLUMNS, _curve_rows

        def blank(p: Point) -> list[list[str]]:
            return [[_cell(g), "", "", ""] for g in p.scene.gaps]
    with atomic_open(out, newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*axes, *columns])
        for p, k in zip(points, keys, strict=True):
            head = [p.axes.get(a, "") for a in axes]
            curve = curves.get(k)
            if curve is None:
                status = "failed" if k in failures else "missing"
                reason = failures.get(k, "not in the store: run `wetcontact sweep` first")
                for cells in blank(p):
                    w.writerow([*head, p.model, *cells, status, reason])
                    counts[status] += 1
                continue
            for cells, status in rows_of(curve):
                w.writerow([*head, p.model, *cells, status, ""])
                counts[status] += 1
    counts["rows"] = sum(v for k, v in counts.items() if k != "rows")
    return counts


def _collision_rows(curve: ForceCurve):
    """The one row of a collision record (:data:`COLLISION_COLUMNS` after ``force_set``,
    before ``status``)."""
    from wetcontact.collide.record import collision_from_curve

    c = collision_from_curve(curve)
    yield ([_cell(c.restitution), c.outcome, _cell(c.stokes_number),
            _cell(c.contact_velocity), _cell(c.rebound_velocity),
            _cell(c.liquid.get("transfer_fraction")), _cell(c.liquid.get("bridge_volume")),
            c.models.get("viscous") or "", c.models.get("capillary") or ""], "ok")


def _curve_rows(curve: ForceCurve):
    """Each gap's cells and status: ``no-bridge`` where the model says the bridge does not
    exist (``meniscus``: ``bridge_exists``) or, for a closure, at and past its own rupture
    distance, where its capillary force is 0."""
    fv, fc, ft = curve.force_viscous, curve.force_capillary, curve.force_total
    exists = curve.extras.get("bridge_exists")
    sc = curve.extras.get("rupture_distance")
    if exists is None and sc is not None and fc is not None:
        exists = ~((curve.gap >= sc) & (fc == 0.0))
    for i, g in enumerate(curve.gap):
        status = "no-bridge" if exists is not None and not np.asarray(exists)[i] else "ok"
        yield ([_cell(g), _cell(None if fv is None else fv[i]),
                _cell(None if fc is None else fc[i]),
                _cell(None if ft is None else ft[i])], status)
