""""Model no more than a scene needs": the cheapest model that meets a tolerance.

Candidates are the registered models that apply to the scene, cheapest first (lowest
level, then lowest declared ``cost`` per gap). A closure is accepted when its a-priori
error estimate, evaluated along the scene's gaps, stays below the tolerance everywhere;
a solver (level >= 1) when its declared accuracy at a preset meets it (attribute
``error_bound``: preset name -> relative error). If nothing qualifies, the
highest-fidelity applicable model is returned with the reason.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wetcontact.errors import InputError
from wetcontact.models import Model, load_all
from wetcontact.scene import Scene


@dataclass(frozen=True)
class Choice:
    """The selected model, the preset to run it at, and why."""

    model: Model
    preset: str
    reason: str


def choose_model(scene: Scene, tolerance: float) -> Choice:
    """Cheapest applicable model whose error estimate is below ``tolerance``.

    Parameters
    ----------
    scene
        The scene to solve.
    tolerance
        Requested relative accuracy of the force, in (0, 1).
    """
    if not 0.0 < tolerance < 1.0:
        raise InputError(f"tolerance = {tolerance!r}; allowed: (0, 1) relative")
    applicable = [m for m in load_all().values() if m.applicable(scene) is None]
    if not applicable:
        raise InputError(f"no registered model applies to scene '{scene.name}'")
    applicable.sort(key=lambda m: (m.level, m.cost, m.name))
    for m in applicable:
        if m.level == 0:
            est = m.force(scene).error_estimate
            if est is not None and np.all(est <= tolerance):
                return Choice(m, "default", f"a-priori error {est.max():.2g} <= {tolerance:g}")
        else:
            acc = m.error_bound
            for preset in ("fast", "default", "accurate"):
                if preset in acc and acc[preset] <= tolerance:
                    return Choice(m, preset, f"preset '{preset}' accuracy {acc[preset]:.1g} "
                                  f"<= {tolerance:g}")
    best = applicable[-1]
    return Choice(best, "accurate" if best.level else "default",
                  f"no model guarantees {tolerance:g}; using the highest-fidelity one")
