r"""Rupture distance of a bridge stretched at constant speed (the dynamic rupture law).

A bridge of volume V (units R^3; R the sphere radius) starts as the static meniscus at the
gap ``S_0 = start S_c`` (``S_c`` the static fold of ``meniscus``, the quasi-static rupture
distance) and is stretched at the constant relative speed v, ``Ca = eta v / sigma``, until
its neck pinches (:func:`~.pinch.locate_pinch`); the rupture distance is the gap at the
pinch, ``S_c(Ca)``. Pitois, Moucheront & Chateau (2001) give
``S_c(Ca) = S_c (1 + Ca^(1/2))`` (PHYSICS.md section 8).

Geometries: a sphere and a wall (``"wall"``), or two spheres (``"pair"``; angles up to
:data:`PAIR_THETA_MAX`): equal spheres are solved on the upper half above the shear-free
mid-plane (the half moves at v/2), unequal ones (``radius_ratio`` = R2/R of the lower
sphere, R the upper's) on the whole bridge. Contact angles equal
on both solids, static (the lines slide at the static angle), Navier slip ``slip`` R on both
solids. Units R = sigma = eta = 1.

Presets (:class:`Preset`, :data:`PRESETS`): the steps are controlled by the neck's local
error (``Stepping.tolerance``): long while the bridge follows its static branch, short in
the slow passage past the fold where the rupture distance is decided, and by the neck's
relative change per step near the pinch; the largest step is a gap step proportional to
S_c (:func:`gap_step`). Accuracy of the rupture distance against the accurate preset
(``benchmarks/bench_dynamic_rupture.py``; V/R^3 = 1e-3, 30 deg; sphere-wall at Ca = 1e-2
and 1e-4, equal spheres at 1e-2): default 3.2-4.2e-4, fast 5.0-6.7e-4; the convergence is
second order in the step the tolerance sets (error ~ tolerance^(2/3); observed 2.2). The
mesh is the same in every preset (twice as fine: 3.3e-4 at Ca = 1e-4).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import NamedTuple

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus import Bridge, rupture_distance
from wetcontact.solver.stokes_dynamic.domain import MeshOptions
from wetcontact.solver.stokes_dynamic.pinch import locate_pinch
from wetcontact.solver.stokes_dynamic.run import Stepping, run
from wetcontact.solver.stokes_dynamic.step import Wetting

KINDS = ("wall", "pair")


class Preset(NamedTuple):
    """The steps of a rupture run.

    Attributes
    ----------
    gap_step
        The largest step, in gap (R) at S_c = :data:`S_REF` (:func:`gap_step`).
    neck_step
        The largest relative change of the neck radius per step (``Stepping.neck_step``).
    tolerance
        The neck's local error per step relative to its start (``Stepping.tolerance``).
    """

    gap_step: float
    neck_step: float
    tolerance: float

    def largest_gap_step(self, static_gap: float) -> float:
        """The largest gap step (R) of a run whose static fold is ``static_gap``: the
        preset's, scaled with ``S_c / S_REF`` (the error control shortens it where the
        neck needs it)."""
        return self.gap_step * static_gap / S_REF


PRESETS: dict[str, Preset] = {
    "fast": Preset(5e-4, 0.05, 4e-6),
    "default": Preset(5e-4, 0.05, 2e-6),
    "accurate": Preset(5e-4, 0.025, 3e-7),
}
"""The steps of each preset."""
S_REF = 0.11037
"""S_c/R at which the presets' gap steps are stated."""
START = 0.2
"""The run starts from the static meniscus at ``START * S_c``."""
NECK_STOP = 0.011
"""The run stops when the neck is this fraction of its start (the last decade is fitted)."""
CA_RANGE = (1e-8, 0.3)
"""Capillary numbers the method is used for; above 0.3 the stretched thread's mesh fails
(at Ca = 1, V/R^3 = 1e-3, 20 deg: a degenerate P2 element after 52 remeshings, at
S = 2.6 S_c)."""
VOLUME_RANGE = (1e-4, 0.1)
RADIUS_RATIO_RANGE = (0.1, 10.0)
"""R2/R of the lower sphere of a pair."""
THETA_RANGE = (1.0, 60.0)
"""deg."""
PAIR_THETA_MAX = 30.0
"""deg: the largest angle between equal spheres. Above about 33 deg (V/R^3 1e-4 to 1e-2)
the static branch ends at a symmetry-breaking bifurcation before its fold (``meniscus``'s
``Division.end``); the upper half above a symmetry plane cannot follow it (at 50 deg and
Ca = 1e-4 it ruptured at 1.07 times the static rupture distance, against 1.013 at 30)."""


@dataclass(frozen=True)
class RuptureCase:
    """One stretching run (units R, sigma, eta; angles in deg).

    ``radius_ratio``: R2/R of the lower sphere of a pair (1: equal spheres); R, the upper
    sphere's radius, is the unit of the volume and of the gaps.
    """

    kind: str
    capillary_number: float
    volume: float
    theta_deg: float
    slip: float = 1e-3
    radius_ratio: float = 1.0

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"dynamic rupture: kind = {self.kind!r}; allowed: {KINDS}")
        checks = (("capillary_number", self.capillary_number, CA_RANGE),
                  ("volume", self.volume, VOLUME_RANGE),
                  ("theta_deg", self.theta_deg, THETA_RANGE),
                  ("slip", self.slip, (1e-5, 1e-2)),
                  ("radius_ratio", self.radius_ratio, RADIUS_RATIO_RANGE))
        for name, value, (lo, hi) in checks:
            if not (math.isfinite(value) and lo <= value <= hi):
                raise InputError(f"dynamic rupture: {name} = {value!r}; allowed: "
                                 f"[{lo:g}, {hi:g}]")
        if self.kind == "wall" and self.radius_ratio != 1.0:
            raise InputError(f"dynamic rupture: radius_ratio = {self.radius_ratio!r} on a "
                             "wall; allowed: 1 (a radius ratio is a pair's)")
        if self.kind == "pair" and self.theta_deg > PAIR_THETA_MAX:
            raise InputError(f"dynamic rupture: theta_deg = {self.theta_deg!r} between two "
                             f"spheres; allowed: up to {PAIR_THETA_MAX:g} (above, the static "
                             "bridge between equal spheres breaks its symmetry before its "
                             "fold, which the symmetric half cannot follow)")

    @property
    def half(self) -> bool:
        """Solved on the upper half above a symmetry plane (equal spheres)."""
        return self.kind == "pair" and self.radius_ratio == 1.0

    @property
    def radius2(self) -> float | None:
        """R2/R of a lower sphere solved as a solid (unequal spheres), else ``None``."""
        return self.radius_ratio if self.kind == "pair" and not self.half else None


@dataclass(frozen=True)
class RuptureResult:
    """The rupture of one run.

    Attributes
    ----------
    static_gap
        S_c of ``meniscus`` (R): the static fold.
    gap
        S_c(Ca) (R): the gap at the pinch.
    ratio
        ``gap / static_gap``.
    slope, spread
        The neck's fitted -dh/dt over its last decade (sigma/eta) and the spread of the
        local slopes (:class:`~.pinch.Pinch`).
    volume_error
        Largest relative volume error over the run.
    steps, remeshes, wall_time
        Time steps, gmsh remeshings, seconds.
    """

    static_gap: float
    gap: float
    ratio: float
    slope: float
    spread: float
    volume_error: float
    steps: int
    remeshes: int
    wall_time: float


def static_fold(case: RuptureCase) -> float:
    """S_c/R of the static meniscus (the fold of the volume-controlled branch)."""
    th = math.radians(case.theta_deg)
    br = Bridge(radius=1.0, radius2=case.radius_ratio if case.kind == "pair" else None,
                contact_angle1=th, contact_angle2=th, surface_tension=1.0)
    return float(rupture_distance(br, case.volume))


def gap_step(preset: str, static_gap: float) -> float:
    """The largest gap step (R) of a rupture run at the named preset
    (:meth:`Preset.largest_gap_step`)."""
    return PRESETS[preset].largest_gap_step(static_gap)


def scaled_gap_step(base: float, static_gap: float, capillary_number: float) -> float:
    """``base`` (R, a step at S_c = :data:`S_REF` and Ca >= 1e-2) times ``S_c / S_REF`` and
    ``min(1, (Ca / 1e-2)^(1/3))``."""
    return base * static_gap / S_REF * min(1.0, (capillary_number / 1e-2) ** (1.0 / 3.0))


def dynamic_rupture(case: RuptureCase, preset: str = "default", steps: Preset | None = None
                    ) -> RuptureResult:
    """Stretch the bridge of ``case`` at its capillary number from ``START * S_c`` to its
    pinch and return the rupture distance (``steps``: other steps than the preset's).

    Raises
    ------
    SolverError
        The run ended before the pinch (a failed mesh, the step limit), with its reason.
    """
    if preset not in PRESETS:
        raise InputError(f"dynamic rupture: preset = {preset!r}; allowed: {tuple(PRESETS)}")
    t0 = time.perf_counter()
    steps = PRESETS[preset] if steps is None else steps
    sc = static_fold(case)
    half = case.half  # the upper half: half the gap, volume and speed
    scale = 2.0 if half else 1.0
    speed = case.capillary_number / scale
    step = steps.largest_gap_step(sc) / scale
    th = math.radians(case.theta_deg)
    wet = Wetting(th, th, case.slip, case.slip)
    r = run(case.volume / scale, START * sc / scale, speed, wet,
            Stepping(dt=step / speed, gap_end=20.0 * sc / scale, neck_stop=NECK_STOP,
                     neck_step=steps.neck_step, tolerance=steps.tolerance),
            MeshOptions(plane="symmetry" if half else "wall", radius2=case.radius2))
    if r.stopped != "neck":
        raise SolverError(f"dynamic rupture {asdict(case)}: the run stopped before the pinch "
                          f"({r.stopped}: {r.message})")
    p = locate_pinch(r)
    gap = p.gap * scale
    return RuptureResult(
        static_gap=sc, gap=gap, ratio=gap / sc, slope=p.slope, spread=p.spread,
        volume_error=float(np.abs(r.volume * scale / case.volume - 1.0).max()),
        steps=r.steps, remeshes=r.remeshes, wall_time=time.perf_counter() - t0)
