"""One comparison of a force curve with a reference curve: the package's only error metric.

:func:`compare` returns a :class:`Comparison` record; the report's tables, the closure
error table, (later) calibration and the tests all use it, so every error quoted anywhere
is computed the same way:

- relative error ``e_i = |F_i - F_ref,i| / |F_ref,i|`` over the gaps where the reference is
  non-zero (``|F_ref| > 1e-12 max |F_ref|``); its maximum, mean and 95th percentile
  (``numpy.percentile``, linear interpolation) and the gap where the maximum sits;
- ``spurious``: gaps where the reference is zero (no liquid there, past rupture) but the
  compared curve is not;
- the signed per-gap error ``F_i / F_ref,i - 1`` over the same gaps (positive: the curve
  over-predicts), kept for tables that show the direction of an error. Its absolute value
  equals ``e_i`` up to round-off (the two are evaluated in their own forms).

:func:`reference_for` picks the reference of a component among the curves at hand by the
models' declared :attr:`~wetcontact.models.Model.reference_rank`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.models import ForceCurve, get_model

COMPONENTS = ("viscous", "capillary", "total")
ZERO_REL = 1e-12  # a reference force below this fraction of its maximum counts as zero
CSV_FIELDS = ("case", "component", "closure", "reference", "points", "max_rel_error",
              "mean_rel_error", "p95_rel_error", "spurious", "gap_of_max_m")


@dataclass(frozen=True)
class Comparison:
    """Error statistics of one curve against a reference, for one force component.

    Attributes
    ----------
    case, model, reference, component
        Scene name, compared model, reference model, force component.
    points
        Number of gaps where the reference is non-zero (the gaps compared).
    max_rel_error, mean_rel_error, p95_rel_error
        Statistics of ``|F - F_ref| / |F_ref|`` over those gaps; NaN when ``points == 0``.
    spurious
        Gaps where the reference is zero but the curve is not.
    gap_of_max
        Gap (m) of the largest relative error; NaN when ``points == 0``.
    gap, rel_error, signed_error
        The compared gaps (m), ``|F - F_ref| / |F_ref|`` and ``F / F_ref - 1`` there.
    """

    case: str
    model: str
    reference: str
    component: str
    points: int
    max_rel_error: float
    mean_rel_error: float
    p95_rel_error: float
    spurious: int
    gap_of_max: float
    gap: np.ndarray
    rel_error: np.ndarray
    signed_error: np.ndarray

    def as_row(self) -> dict[str, Any]:
        """The summary as one CSV row (columns :data:`CSV_FIELDS`)."""
        return {"case": self.case, "component": self.component, "closure": self.model,
                "reference": self.reference, "points": self.points,
                "max_rel_error": self.max_rel_error, "mean_rel_error": self.mean_rel_error,
                "p95_rel_error": self.p95_rel_error, "spurious": self.spurious,
                "gap_of_max_m": self.gap_of_max}

    def rel_at(self, gap: float) -> float:
        """Relative error ``|F - F_ref|/|F_ref|`` at ``gap``; NaN if not compared there."""
        hit = np.nonzero(self.gap == gap)[0]
        return float(self.rel_error[hit[0]]) if hit.size else float("nan")

    def signed_at(self, gap: float) -> float:
        """Signed error ``F/F_ref - 1`` at ``gap``; NaN if that gap was not compared."""
        hit = np.nonzero(self.gap == gap)[0]
        return float(self.signed_error[hit[0]]) if hit.size else float("nan")


def component_of(curve: ForceCurve, component: str) -> np.ndarray | None:
    """The force component of ``curve`` (``None`` if the model does not model it)."""
    if component not in COMPONENTS:
        raise InputError(f"component = {component!r}; allowed: " + ", ".join(COMPONENTS))
    return curve.force_total if component == "total" else getattr(curve, f"force_{component}")


def _modelled(curve: ForceCurve) -> str:
    """The force components a curve models, e.g. ``"viscous + capillary"``."""
    return " + ".join(c for c in ("viscous", "capillary")
                      if getattr(curve, f"force_{c}") is not None) or "none"


def compare(curve: ForceCurve, reference: ForceCurve, component: str) -> Comparison:
    """Compare ``curve`` with ``reference`` gap by gap for one force component.

    Parameters
    ----------
    curve, reference
        Curves on the same gaps (an :class:`InputError` otherwise).
    component
        ``"viscous"``, ``"capillary"`` or ``"total"``; both curves must model it.
    """
    f, ref = component_of(curve, component), component_of(reference, component)
    if component == "total" and _modelled(curve) != _modelled(reference):
        raise InputError(f"compare: total of '{curve.model}' ({_modelled(curve)}) against "
                         f"'{reference.model}' ({_modelled(reference)}); allowed: curves "
                         "that model the same force components (compare each component)")
    if f is None or ref is None:
        missing = curve.model if f is None else reference.model
        raise InputError(f"compare: model '{missing}' has no {component} force")
    if curve.gap.shape != reference.gap.shape or not np.array_equal(curve.gap, reference.gap):
        raise InputError(f"compare: '{curve.model}' and '{reference.model}' curves of "
                         f"'{curve.case}' are on different gaps")
    scale = np.max(np.abs(ref))
    nz = np.abs(ref) > ZERO_REL * scale if scale > 0 else np.zeros(ref.shape, bool)
    rel = np.abs(f[nz] - ref[nz]) / np.abs(ref[nz])
    signed = f[nz] / ref[nz] - 1.0
    gap = curve.gap[nz]
    nan = float("nan")
    return Comparison(
        case=curve.case, model=curve.model, reference=reference.model, component=component,
        points=int(nz.sum()),
        max_rel_error=float(rel.max()) if rel.size else nan,
        mean_rel_error=float(rel.mean()) if rel.size else nan,
        p95_rel_error=float(np.percentile(rel, 95)) if rel.size else nan,
        spurious=int(np.sum(~nz & (np.abs(f) > 0))),
        gap_of_max=float(gap[np.argmax(rel)]) if rel.size else nan,
        gap=gap, rel_error=rel, signed_error=signed,
    )


def pooled(records: Iterable[Comparison]) -> dict[str, float | int]:
    """Max, mean and 95th percentile of the relative error over several records' gaps.

    For a table row that summarises many curves (e.g. one closure over a parameter grid):
    the statistics of the concatenated per-gap errors, as :func:`compare` defines them.
    """
    recs = list(records)
    rel = np.concatenate([r.rel_error for r in recs]) if recs else np.zeros(0)
    nan = float("nan")
    return {"points": int(rel.size), "spurious": sum(r.spurious for r in recs),
            "max_rel_error": float(rel.max()) if rel.size else nan,
            "mean_rel_error": float(rel.mean()) if rel.size else nan,
            "p95_rel_error": float(np.percentile(rel, 95)) if rel.size else nan}


def reference_for(curves: Mapping[str, ForceCurve], component: str) -> str | None:
    """The highest-ranked reference model for ``component`` among ``curves`` (or None).

    Ranks come from each model's ``reference_rank`` (e.g. the exact ``brenner`` series above
    ``stokes``, ``thinfilm`` and ``lubrication`` for the viscous force; ``meniscus`` for the
    capillary force).
    """
    ranked = [(get_model(name).reference_rank.get(component, 0), name)
              for name, c in curves.items() if component_of(c, component) is not None]
    ranked = [(r, n) for r, n in ranked if r > 0]
    return max(ranked)[1] if ranked else None
