""""Model no more than a scene needs", chosen per force component.

A scene needs a viscous force (immersed, or any liquid with a non-zero approach speed) and
a capillary force (films and bridges). For each needed component the candidates are the
registered models that apply to the scene and model that component, cheapest first (level,
then declared ``cost``, then preset fast -> accurate). A candidate is eligible when its
**error bound for that component** is known at every gap of the scene and at most the
tolerance there:

- closures (level 0): the measured held-out tables of
  :mod:`wetcontact.reduced_models.bounds` (outside their bins: not eligible); ``brenner`` is
  the exact series (1e-12, summation accuracy);
- ``stokes``: its measured preset accuracy on immersed scenes. On films its flat top is the
  viscous reference of the closures and of ``lubrication`` (the fast-impact limit: no
  suction, no deformation of the film surface, whose model error against a deforming film
  is not measured); its own discretisation error there is not tabulated, so it is not
  eligible;
- ``lubrication``: its fast/default presets on bridges measured against a 256-cell
  solution; on films against Stokes' flat-top film, which adds its model error (up to
  73 % as the sphere leaves the film). The bridge bounds of every viscous model are
  relative to the thin-gap model: they do not cover the moving contact lines' dissipation,
  which ``stokes`` adds (19 % at S/R = 1e-3, V/R^3 = 1e-3, 20 deg, 1 nm slip; several
  times the thin-gap force beyond S/R = 1e-2);
- ``meniscus``: its preset accuracy against the shooting solution (static bridge);
- ``thinfilm``: capillary component only, the bound of its penalty meniscus contact
  (first order in the wetting width: at most 4 % at lambda = 0.05, plus the small-slope
  meniscus's 6-11 % deficit against the finite-element bridge), conservative for the
  default sharp contact (numerical error 0.3 % at the default preset). Its viscous force
  is not eligible: its meniscus wets a larger zone than the flat film top, the films'
  viscous reference, and the two differ by 1.2-40x (a different film model).

If no candidate meets the tolerance for a component, the one with the smallest bound is
used (a costlier one only if it cuts the bound by :data:`FALLBACK_RATIO`) and the choice
says so (``met = False``). Both models run, and one curve is returned:
``force_viscous`` from the viscous choice, ``force_capillary`` from the capillary one, and
the per-component bounds as extras ``error_estimate_viscous`` / ``error_estimate_capillary``
(``error_estimate`` is their maximum per gap). For a bridge, the viscous force is 0 at
the gaps at or past the capillary model's rupture distance (no bridge, no liquid between
the surfaces); the thin-gap viscous models alone would still give one there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.fileio import json_ready
from wetcontact.models import PRESETS, ForceCurve, Model, load_all, model_instead, provenance
from wetcontact.reduced_models import bounds
from wetcontact.scene import TOLERANCE_RANGE, Scene, plain_number

#: exact series (Brenner 1961): summation accuracy, 1e-15 measured against a 40-digit sum
EXACT_BOUND = 1e-12
#: thinfilm per preset: (viscous, capillary) relative bounds; lambda = 0.2 / 0.05 / 0.025
#: gives <= 16 / 4 / 2 % (first order in lambda, 4 % measured at 0.05), plus the model
#: error: viscous 0.9 % against lubrication, suction 11 % against the FE bridge (README).
#: Measured for the penalty meniscus; kept (conservative) for the sharp contact, the
#: default since issue 13 (numerical error 0.04 % at default; suction within 1 % of the FE
#: bridge of the wetted volume only for Ca* <= 2e-3) until its model error is measured
THINFILM_BOUND = {"fast": (0.17, 0.27), "default": (0.05, 0.15), "accurate": (0.03, 0.13)}
COMPONENTS = ("viscous", "capillary")
#: when nothing meets the tolerance, a costlier model must cut the bound by this factor
FALLBACK_RATIO = 1.5


@dataclass(frozen=True)
class Choice:
    """The model chosen for one force component, its preset, bound and why.

    Attributes
    ----------
    component
        ``"viscous"`` or ``"capillary"``.
    model, preset
        The model and the preset to run it at.
    bound
        Relative error bound of that component per gap (finite, > 0).
    reference
        What the bound was measured against.
    met
        True if ``bound <= tolerance`` at every gap.
    reason
        One line for the user.
    """

    component: str
    model: Model
    preset: str
    bound: np.ndarray
    reference: str
    met: bool
    reason: str


@dataclass(frozen=True)
class Selection:
    """One :class:`Choice` per component the scene needs."""

    tolerance: float
    choices: dict[str, Choice]

    @property
    def reason(self) -> str:
        return "; ".join(f"{c}: {ch.model.name} ({ch.preset}) {ch.reason}"
                         for c, ch in self.choices.items())


def needed_components(scene: Scene) -> tuple[str, ...]:
    """The force components the scene has: viscous if immersed or moving, capillary if a
    free surface is present (film or bridge)."""
    out = []
    if scene.amount == "immersed" or scene.velocity != 0.0:
        out.append("viscous")
    if scene.amount in ("film", "bridge"):
        out.append("capillary")
    return tuple(out)


def component_bound(model: Model, preset: str, component: str,
                    scene: Scene) -> tuple[np.ndarray, str] | str:
    """Relative error bound per gap of ``model`` at ``preset`` for ``component``, and the
    reference it was measured against; or the reason there is none."""
    n = scene.gap_array.size
    if model.component not in (component, "both"):
        return f"does not model the {component} force"
    if model.name == "brenner":
        if scene.slip_length_sphere > 0 or scene.slip_length_wall > 0:
            return "no-slip series; the scene has slip"
        return np.full(n, EXACT_BOUND), "exact series (summation accuracy)"
    if model.level == 0:
        if preset != "default":
            return "closures have one preset"
        sc = None
        if component == "capillary":
            sc = float(model.rupture_distance(scene))  # type: ignore[attr-defined]
        got = bounds.measured_bound(model.name, component, scene, sc)
        if got is None:
            return "no measured error table for this kind of scene"
        if not np.all(np.isfinite(got[0])):
            return bounds.domain_reason(model.name, component, scene, sc)
        floor = getattr(model, "bound_floor", None)  # a closure's known-coarse region
        if floor is not None and np.any((f := floor(scene, sc)) > got[0]):
            return np.maximum(got[0], f), (f"{got[1]}; raised to the closure's own floor at "
                                           f"{int(np.sum(f > got[0]))} of {f.size} gaps (up "
                                           f"to {float(f.max()):.2g})")
        return got
    if model.name == "lubrication":
        got = bounds.measured_bound(f"lubrication:{preset}", component, scene)
        if got is None:
            return f"preset '{preset}' not measured on this kind of scene"
        if not np.all(np.isfinite(got[0])):
            return (f"preset '{preset}': " + bounds.domain_reason(f"lubrication:{preset}",
                                                                  component, scene))
        return got
    if model.name == "thinfilm":
        if component == "viscous":
            return ("viscous force not comparable with the films' flat-top reference (stokes): "
                    "its meniscus wets a larger zone, 1.2-40x the flat-top force on the "
                    "held-out films")
        b = THINFILM_BOUND[preset][1]
        return np.full(n, b), "discretisation + small-slope model error (README)"
    if model.name == "stokes":
        if scene.amount == "film":
            return ("flat film top: the films' viscous reference, its discretisation "
                    "error not tabulated; its model error (no suction) not measured")
        if scene.amount != "immersed":
            return ("quasi-static bridge: the bridge bounds are relative to the thin-gap "
                    "model (no contact-line dissipation); its own not tabulated")
        return (np.full(n, float(model.error_bound[preset])),
                "Brenner's series (measured preset accuracy)")
    if preset in model.error_bound:
        return np.full(n, float(model.error_bound[preset])), "declared preset accuracy"
    return f"no error bound at preset '{preset}'"


def choose(scene: Scene, tolerance: float, preset: str | None = None) -> Selection:
    """Per component, the cheapest applicable model whose bound meets ``tolerance``.

    Parameters
    ----------
    scene
        The scene to solve.
    tolerance
        Requested relative accuracy of each force component, in (0, 1).
    preset
        Restrict solvers to this preset (closures always run at ``default``).
    """
    lo, hi = TOLERANCE_RANGE
    tolerance = plain_number(tolerance)
    if isinstance(tolerance, bool) or not (isinstance(tolerance, float | int)
                                           and lo < tolerance < hi):
        raise InputError(f"tolerance = {tolerance!r}; allowed: ({lo:g}, {hi:g}) relative")
    pool = [m for m in load_all().values() if m.selectable]
    refused = {m.name: (m, why) for m in pool if (why := m.applicable(scene)) is not None}
    models = sorted((m for m in pool if m.name not in refused),
                    key=lambda m: (m.level, m.cost, m.name))
    choices: dict[str, Choice] = {}
    for comp in needed_components(scene):
        best: Choice | None = None
        why_not: list[tuple[str, str]] = []
        for m in models:
            presets = ["default"] if m.level == 0 else [
                p for p in PRESETS if p in m.presets and (preset is None or p == preset)]
            for p in presets:
                got = component_bound(m, p, comp, scene)
                if isinstance(got, str):
                    why_not.append((m.name, got))
                    continue
                b, ref = got
                worst = float(b.max())
                if worst <= tolerance:
                    choices[comp] = Choice(comp, m, p, b, ref, True,
                                           f"bound {worst:.2g} <= {tolerance:g} ({ref})")
                    break
                # fallback: the smallest bound, unless a cheaper one is within FALLBACK_RATIO
                if best is None or worst * FALLBACK_RATIO < float(best.bound.max()):
                    best = Choice(comp, m, p, b, ref, False,
                                  f"no model meets {tolerance:g}; running one with bound "
                                  f"{worst:.2g} ({ref})")
            if comp in choices:
                break
        if comp not in choices:
            if best is None:
                why: dict[str, str] = {}  # a model's first reason (its first preset's)
                for name, reason in why_not:
                    if reason != f"does not model the {comp} force":
                        why.setdefault(name, reason)
                if not why:  # no model accepts: the two most faithful models' refusals
                    mine = sorted((m for m, _ in refused.values()
                                   if m.component in (comp, "both")),
                                  key=lambda m: (-m.reference_rank.get(comp, 0), -m.level,
                                                 m.name))[:2]
                    why = {m.name: refused[m.name][1].removeprefix(f"model '{m.name}': ")
                           for m in mine}
                instead = model_instead(scene, comp)
                raise InputError(f"scene '{scene.name}': no applicable model computes the "
                                 f"{comp} force with a measured error bound; give --model "
                                 + (f"(model '{instead}' applies) " if instead else "")
                                 + "instead. Why not: "
                                 + ("; ".join(f"{n}: {w}" for n, w in why.items())
                                    or "no model of this force accepts the scene"))
            choices[comp] = best
    return Selection(float(tolerance), choices)


def solve(scene: Scene, tolerance: float, preset: str | None = None
          ) -> tuple[ForceCurve, Selection]:
    """Choose per component (:func:`choose`), run the chosen models, return one curve."""
    sel = choose(scene, tolerance, preset)
    runs: dict[tuple[str, str], ForceCurve] = {}
    for ch in sel.choices.values():
        key = (ch.model.name, ch.preset)
        if key not in runs:
            runs[key] = ch.model.force(scene, preset=ch.preset)
    return combine(scene, sel, runs), sel


def combine(scene: Scene, sel: Selection, runs: dict[tuple[str, str], ForceCurve]
            ) -> ForceCurve:
    """One curve from the per-component runs (module docstring)."""
    parts: dict[str, ForceCurve] = {c: runs[(ch.model.name, ch.preset)]
                                    for c, ch in sel.choices.items()}
    fv = parts["viscous"].force_viscous if "viscous" in parts else None
    fc = parts["capillary"].force_capillary if "capillary" in parts else None
    extras: dict[str, np.ndarray] = {}
    for c in ("viscous", "capillary"):  # capillary extras win on a shared name
        if c in parts:
            extras.update(parts[c].extras)
    for c, ch in sel.choices.items():
        extras[f"error_estimate_{c}"] = ch.bound
    est = np.max([ch.bound for ch in sel.choices.values()], axis=0)
    names = list(dict.fromkeys(ch.model.name for ch in sel.choices.values()))
    wall = math.fsum(float(r.diagnostics.get("wall_time_s", 0.0)) for r in runs.values())
    diag: dict[str, Any] = {"wall_time_s": wall}
    settings: dict[str, Any] = {"tolerance": sel.tolerance}
    for c, ch in sel.choices.items():
        diag[c] = json_ready({k: v for k, v in parts[c].diagnostics.items() if k != "wall_time_s"})
        settings[c] = json_ready({"model": ch.model.name, **parts[c].settings})
    if fv is None and fc is None:
        raise InputError(f"scene '{scene.name}' needs no force component")
    if fv is not None and fc is not None and scene.amount == "bridge":
        fv, note = _no_bridge_no_viscous(scene, fv, parts["capillary"])
        if note:
            diag["past_rupture"] = note
    return ForceCurve(case=scene.name, model="+".join(names), gap=scene.gap_array,
                      force_viscous=fv, force_capillary=fc, extras=extras,
                      error_estimate=est, diagnostics=diag, settings=settings,
                      provenance=provenance())


def _no_bridge_no_viscous(scene: Scene, fv: np.ndarray, capillary: ForceCurve
                          ) -> tuple[np.ndarray, str]:
    """The viscous force set to 0 at the gaps at or past the bridge's rupture distance
    given by the capillary model (``rupture_distance``), where there is no bridge and so no
    liquid between the surfaces; the thin-gap viscous models would return a force there.
    Returns the force and a one-line note (empty when no gap is past rupture)."""
    sc = capillary.extras.get("rupture_distance")
    if sc is None:
        return fv, ""
    sc = np.broadcast_to(np.asarray(sc, dtype=float), fv.shape)
    past = np.isfinite(sc) & (scene.gap_array >= sc)
    if not past.any():
        return fv, ""
    return np.where(past, 0.0, fv), (
        f"viscous force 0 at {int(past.sum())} of {past.size} gaps at or past the bridge's "
        f"rupture distance {float(sc[past][0]):.4g} m ({capillary.model}): no bridge there")
