"""Parameter sweeps: solve many (scene, model) points into the reference store.

INTERFACE STAGE: this module fixes the call that the report, calibration and export use
(``sweep(points, store, ...) -> SweepResult``); the body is a serial loop until the Dask
implementation lands. Only the calling process writes the store; a point already in the
store under the same content key is reused, never recomputed.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

from wetcontact.errors import InputError, SolverError
from wetcontact.models import ForceCurve, get_model
from wetcontact.scene import Scene
from wetcontact.store import Store, curve_key

Status = Literal["computed", "reused", "failed"]


@dataclass(frozen=True)
class Point:
    """One unit of work: a scene solved by one model at one preset.

    Attributes
    ----------
    scene
        The scene (its gaps are the gaps solved).
    model
        Registered model name.
    preset
        Resolution preset; a model without it runs at ``"default"``.
    settings
        Extra keyword settings passed to ``model.force`` (e.g. ``inertia=True``); they are
        part of the content key.
    axes
        The study-axis values that made this point (field path -> value), for tables and
        ``export csv``; not part of the key.
    """

    scene: Scene
    model: str
    preset: str = "default"
    settings: Mapping[str, Any] = field(default_factory=dict)
    axes: Mapping[str, Any] = field(default_factory=dict)

    @property
    def run_preset(self) -> str:
        """The preset actually run: ``preset`` if the model has it, else ``"default"``."""
        m = get_model(self.model)
        return self.preset if self.preset in m.presets else "default"

    @property
    def key(self) -> str:
        """Content key in the store (scene, model, settings)."""
        m = get_model(self.model)
        return curve_key(self.scene, self.model,
                         m.settings_for(self.run_preset, **dict(self.settings)))


@dataclass(frozen=True)
class Outcome:
    """What happened to one point: its curve (None when it failed) and why."""

    point: Point
    key: str
    status: Status
    curve: ForceCurve | None = None
    reason: str = ""


@dataclass
class SweepResult:
    """All outcomes of a sweep, in the order of the points given."""

    outcomes: list[Outcome]
    store: str
    wall_time_s: float

    def count(self, status: Status) -> int:
        """Number of points with ``status``."""
        return sum(o.status == status for o in self.outcomes)

    def curve(self, point: Point) -> ForceCurve | None:
        """The curve of ``point`` (None if it failed)."""
        key = point.key
        return next((o.curve for o in self.outcomes if o.key == key), None)


def solve_point(point: Point) -> ForceCurve:
    """Solve one point (what a worker runs)."""
    return get_model(point.model).force(point.scene, preset=point.run_preset,
                                        **dict(point.settings))


def sweep(points: Sequence[Point], store: Store, workers: int | None = None,
          scheduler: str | None = None, progress: bool = True) -> SweepResult:
    """Solve every point not yet in ``store``, save each curve, return all outcomes.

    Parameters
    ----------
    points
        The work; duplicates (same key) are solved once.
    store
        The reference store; only this process writes it.
    workers
        Number of local worker processes (default: one per core).
    scheduler
        Address ``tcp://host:port`` of a running Dask scheduler instead of a local cluster.
    progress
        Show a progress bar on a terminal, a line every few seconds otherwise.
    """
    t0 = time.perf_counter()
    outcomes: list[Outcome] = []
    done: dict[str, Outcome] = {}
    for p in points:
        key = p.key
        if key in done:
            outcomes.append(done[key])
            continue
        if key in store:
            out = Outcome(p, key, "reused", store.load(key))
        else:
            try:
                curve = solve_point(p)
                store.save(p.scene, curve)
                out = Outcome(p, key, "computed", curve)
            except (InputError, SolverError) as exc:
                out = Outcome(p, key, "failed", None, str(exc))
        done[key] = out
        outcomes.append(out)
    return SweepResult(outcomes, str(store.path), time.perf_counter() - t0)
