"""Time stepping of a sphere-wall bridge: kinematic update, volume, mesh motion, remeshing,
stopping (the equations are in :mod:`.step`, the domain in :mod:`.domain`).

One step from t_n to t_{n+1} = t_n + dt (semi-implicit Euler, order 1 in time):

1. solve Stokes on Omega^n with the sphere at the mean speed ``(S_{n+1} - S_n)/dt`` of the
   prescribed gap history and the surface tension at ``x^n + dt u`` (:func:`.step.solve_step`);
2. move the free-surface nodes with the fluid, ``x^{n+1} = x^n + dt u`` (the kinematic
   condition; the wall's contact line slides on z = 0, the sphere's is put back on the
   sphere at S_{n+1});
3. slide the nodes along the new surface back to their reference fractions of its length
   (a tangential motion: the shape is unchanged to the interpolation error);
4. restore the volume by a uniform normal shift of the surface (:func:`.domain.correct_volume`);
5. place the solid and interior nodes (:meth:`.domain.Domain.moved`); remesh with gmsh from
   the surface when an element's shape falls below ``remesh_shape`` of its reference shape
   or its P2 map below ``remesh_curvature``.

Stops at ``t_end`` or ``gap_end``, when the neck radius falls below ``neck_stop`` times its
initial value ("neck"), or when a new mesh is no better ("mesh") or a solve fails
("solver"): the reason is in :attr:`DynamicRun.stopped`, no value is NaN.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import quad

from wetcontact.errors import SolverError
from wetcontact.solver.meniscus import Bridge, meniscus_profile, solve_volume
from wetcontact.solver.stokes_dynamic.domain import (
    Domain,
    MeshOptions,
    correct_volume,
    on_sphere,
    profile_of,
    redistribute,
    sphere_angle,
)
from wetcontact.solver.stokes_dynamic.step import StepSolution, Wetting, solve_step

ORDER = 1
"""Declared order in time of the stepping (semi-implicit Euler)."""


@dataclass(frozen=True)
class Stepping:
    """Time step and stopping rules (units eta R / sigma).

    Attributes
    ----------
    dt
        Time step.
    t_end, gap_end
        Stop at this time, or once the gap passes this S/R (``None``: no limit).
    neck_stop
        Stop when the neck radius falls below this fraction of its initial value.
    remesh_shape, remesh_curvature
        Remesh thresholds (:meth:`~.domain.Domain.quality`).
    max_steps
        Hard limit on the number of steps.
    """

    dt: float
    t_end: float | None = None
    gap_end: float | None = None
    neck_stop: float = 0.2
    remesh_shape: float = 0.4
    remesh_curvature: float = 0.3
    max_steps: int = 100_000

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise SolverError(f"stokes-dynamic: dt = {self.dt!r}; allowed: finite > 0")
        if self.t_end is None and self.gap_end is None:
            raise SolverError("stokes-dynamic: give t_end or gap_end")


@dataclass
class DynamicRun:
    """History of a dynamic bridge (units R, sigma, eta; force on the sphere in sigma R,
    positive pushing apart; arrays per saved state, the first the initial one).

    Attributes
    ----------
    time, gap, force, neck_radius, volume
        Per step. ``force[k]`` is the force of the step that ended at ``time[k]`` (the
        initial entry holds the first step's force).
    force_wall
        Axial force on the wall (+z); ``force + force_wall`` vanishes in Stokes flow.
    stopped
        Why the run ended: ``"t_end"``, ``"gap_end"``, ``"neck"``, ``"mesh"``, ``"solver"``,
        ``"max_steps"``; ``message`` has the details.
    remeshes, steps, wall_time
        Number of gmsh remeshings, time steps, and seconds.
    domain
        The last domain (its free surface: ``domain.surface_xy``).
    """

    time: np.ndarray
    gap: np.ndarray
    force: np.ndarray
    force_wall: np.ndarray
    neck_radius: np.ndarray
    volume: np.ndarray
    stopped: str
    message: str
    remeshes: int
    steps: int
    wall_time: float
    domain: Domain = field(repr=False)
    diagnostics: dict[str, float] = field(default_factory=dict)


def static_profile(gap: float, volume: float, wet: Wetting) -> np.ndarray:
    """The static meniscus (n, 2) at ``gap`` (S/R) and ``volume`` (V/R^3), units R
    (:func:`wetcontact.solver.meniscus.solve_volume`)."""
    br = Bridge(radius=1.0, contact_angle1=wet.theta_sphere, contact_angle2=wet.theta_wall,
                surface_tension=1.0)
    sol = solve_volume(br, gap, volume)
    if not sol.exists:
        raise SolverError(f"stokes-dynamic: no static bridge at S/R = {gap:g}, V/R^3 = "
                          f"{volume:g} ({sol.message})")
    prof = meniscus_profile(sol, n=801)
    return np.column_stack([prof["r"], prof["z"]])


def gap_history(gap0: float, speed: float | Callable[[float], float]
                ) -> Callable[[float], float]:
    """S(t) from S(0) = gap0 and dS/dt = speed (a constant or a function of t)."""
    if callable(speed):
        return lambda t: gap0 + quad(speed, 0.0, t, limit=200)[0]
    v = float(speed)
    return lambda t: gap0 + v * t


def run(volume: float, gap0: float, speed: float | Callable[[float], float], wet: Wetting,
        stepping: Stepping, mesh: MeshOptions | None = None,
        initial: np.ndarray | None = None, intorder: int = 4) -> DynamicRun:
    """Follow a sphere-wall bridge of ``volume`` (V/R^3) from ``gap0`` (S/R) with the sphere
    moving at ``speed`` = dS/dt (units sigma/eta, i.e. the capillary number; > 0
    separating).

    ``initial``: the free surface (n, 2) at t = 0, from the wall's contact line to a point
    on the sphere (default: the static meniscus); its volume is corrected to ``volume``.
    """
    t_start = time.perf_counter()
    opts = mesh or MeshOptions()
    prof = static_profile(gap0, volume, wet) if initial is None else np.asarray(initial)
    gap_at = gap_history(gap0, speed)
    dom = Domain.from_profile(gap0, prof, opts)
    xs, shift = correct_volume(dom.surface_xy, gap0, volume)
    if abs(shift) > 0.1 * opts.contact_size:  # a large correction: mesh the corrected shape
        dom = Domain.from_profile(gap0, profile_of(xs), opts)
        xs, _ = correct_volume(dom.surface_xy, gap0, volume)
    dom = dom.moved(xs, gap0)
    neck0 = dom.neck()[0]
    hist: dict[str, list[float]] = {k: [] for k in ("t", "S", "F", "Fw", "neck", "V")}
    remeshes, stopped, message = 0, "", ""
    t, step = 0.0, 0
    dt = stepping.dt
    sol: StepSolution | None = None

    def record(t_: float, d: Domain, s: StepSolution) -> None:
        hist["t"].append(t_)
        hist["S"].append(d.gap)
        hist["F"].append(s.force)
        hist["Fw"].append(s.force_wall)
        hist["neck"].append(d.neck()[0])
        hist["V"].append(d.volume())

    while True:
        if step >= stepping.max_steps:
            stopped, message = "max_steps", f"{step} steps"
            break
        t1 = t + dt
        s1 = gap_at(t1)
        try:
            sol = solve_step(dom, dt, (s1 - dom.gap) / dt, wet, intorder=intorder)
        except SolverError as exc:
            stopped, message = "solver", str(exc)
            break
        if step == 0:
            record(0.0, dom, sol)
        u = sol.velocity(dom.surface)
        xs = dom.surface_xy + dt * u
        xs[1, 0] = 0.0
        xs[:, -1] = on_sphere(sphere_angle(xs[:, -1:], s1), s1)[:, 0]
        if np.any(xs[0] <= 0) or not np.all(np.isfinite(xs)):
            stopped, message = "neck", f"the free surface reached the axis at t = {t1:.6g}"
            break
        xs = redistribute(xs, dom.fractions["surface"])
        try:
            xs, _ = correct_volume(xs, s1, volume)
        except SolverError as exc:
            stopped, message = "solver", str(exc)
            break
        new = dom.moved(xs, s1)
        shape, curv = new.quality()
        if shape < stepping.remesh_shape or curv < stepping.remesh_curvature:
            try:
                new = Domain.from_profile(s1, profile_of(xs), opts)
                xs2, _ = correct_volume(new.surface_xy, s1, volume)
                new = new.moved(xs2, s1)
            except SolverError as exc:
                stopped, message = "mesh", f"remeshing at t = {t1:.6g} failed: {exc}"
                break
            remeshes += 1
            shape, curv = new.quality()
            if curv < stepping.remesh_curvature:
                stopped, message = "mesh", (f"a new mesh at t = {t1:.6g} has a P2 map ratio "
                                            f"{curv:.3g} < {stepping.remesh_curvature}")
                break
        dom, t, step = new, t1, step + 1
        record(t, dom, sol)
        r_neck = hist["neck"][-1]
        if r_neck < stepping.neck_stop * neck0:
            stopped, message = "neck", (f"neck radius {r_neck:.4g} R < {stepping.neck_stop} "
                                        f"times the initial {neck0:.4g} R at t = {t:.6g}")
            break
        if stepping.t_end is not None and t >= stepping.t_end - 1e-12 * max(1.0, t):
            stopped, message = "t_end", f"t = {t:.6g}"
            break
        if stepping.gap_end is not None and (dom.gap - stepping.gap_end) * (
                dom.gap - gap0) >= 0 and dom.gap != gap0:
            stopped, message = "gap_end", f"S/R = {dom.gap:.6g}"
            break
    if not hist["t"]:
        raise SolverError(f"stokes-dynamic: the first step failed: {message}")
    arr = {k: np.asarray(v, dtype=float) for k, v in hist.items()}
    return DynamicRun(time=arr["t"], gap=arr["S"], force=arr["F"], force_wall=arr["Fw"],
                      neck_radius=arr["neck"], volume=arr["V"], stopped=stopped,
                      message=message, remeshes=remeshes, steps=step,
                      wall_time=time.perf_counter() - t_start, domain=dom,
                      diagnostics={"ndofs": float(sol.ndofs) if sol else 0.0,
                                   "elements": float(dom.mesh.t.shape[1])})
