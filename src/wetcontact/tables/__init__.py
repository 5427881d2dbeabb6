"""Report sections: one module per study.

Every module has ``points(ctx) -> list[Point]`` (the study's work, swept into the store by
``wetcontact run`` before anything is drawn), optionally ``derived_points(ctx, result)``
(a second stage whose axes depend on the first stage's curves, e.g. gaps as fractions of
the rupture distance), and ``section(out, result, ctx) -> str``, a renderer that takes the
swept curves from ``result`` (a :class:`~wetcontact.sweep.SweepResult`), compares them
with :func:`wetcontact.compare.compare`, writes its CSV/PNG files into ``out`` and returns
the Markdown of ``reports/README.md``. Renderers never solve a model and never read the
repository: what they need besides the curves comes in the :class:`StudyContext`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from wetcontact.scene import Scene


@dataclass(frozen=True)
class StudyContext:
    """What a study needs besides the store.

    Attributes
    ----------
    quick
        Smoke run: fast presets, fewer points.
    scenes
        The cases given to ``wetcontact run`` (the thin-film study takes its film cases
        from them).
    bench
        The thin-film benchmark's results (``benchmarks/results/thinfilm.json``) when
        given, for the stability map and the wetting-width study; ``None`` otherwise.
    bench_path
        Where ``bench`` was read from (quoted in the report).
    calibration
        ``(path, data)`` of each calibration JSON (``wetcontact calibrate``, e.g.
        ``benchmarks/results/calibration/*.json``), for the held-out tables.
    calibrated_viscous, calibrated_viscous_path
        The shipped ``calibrated-viscous`` closure's table (its package data) and its path.
    calibrated_capillary, calibrated_capillary_path
        The same for ``calibrated-capillary``.
    """

    quick: bool = False
    scenes: tuple[Scene, ...] = ()
    bench: dict[str, Any] | None = field(default=None, compare=False)
    bench_path: str = ""
    calibration: tuple[tuple[str, dict[str, Any]], ...] = field(default=(), compare=False)
    calibrated_viscous: dict[str, Any] | None = field(default=None, compare=False)
    calibrated_viscous_path: str = ""
    calibrated_capillary: dict[str, Any] | None = field(default=None, compare=False)
    calibrated_capillary_path: str = ""
