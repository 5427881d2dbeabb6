"""Time stepping of a bridge between a sphere and a wall, a symmetry plane or a lower sphere:
kinematic update, volume, mesh motion, remeshing, stopping (the equations are in
:mod:`.step`, the domain in :mod:`.domain`).

One step from t_n to t_{n+1} = t_n + dt (variable-step BDF2, order 2 in time; the first
step backward Euler on the current domain, at ``first`` dt, the next ones growing by
``max_ratio``):

1. predict the domain at t_{n+1} by linear extrapolation of the surface,
   ``x* = x^n + omega (x^n - x^{n-1})`` (omega = dt_n/dt_{n-1}), its ends put back on the
   solids at S_{n+1}, the other nodes by the mesh motion;
2. on it solve Stokes at t_{n+1} (sphere speed dS/dt(t_{n+1})) with the surface tension at
   the new surface ``x^{n+1} = a0 x^n + a1 x^{n-1} + c dt w`` (:func:`bdf_weights`; the
   mesh velocity w is the fluid's u, implicit, plus the tangential part of the history's
   slide ``(x^n - x^{n-1})/dt_{n-1} - u^n`` that keeps the nodes at their fractions of the
   surface; :func:`.step.solve_step`);
3. slide the nodes along the new surface to their reference fractions of its length;
4. restore the volume by a normal shift of the surface (:func:`.domain.correct_volume`);
5. place the solid and interior nodes (:meth:`.domain.Domain.moved`); remesh with gmsh from
   the surface when an element's shape falls below ``remesh_shape`` of its reference shape
   or its P2 map below ``remesh_curvature``; the history x^n, u^n is carried to the new
   mesh at its surface fractions (no restart). A new mesh whose P2 map is itself below
   ``remesh_curvature`` (gmsh's corner element in a thin wedge at a small contact angle) is
   kept down to :data:`CURVATURE_FLOOR` of it and remeshed when its map falls to
   :data:`CURVATURE_DROP` of its start.

Force timing: ``force[k]`` is the force at ``time[k]`` (second order: the Stokes problem of
step 2 is the one at t_{n+1}); the first entry is the instantaneous Stokes flow of the
initial shape (``dt = 0``). Adaptive steps keep the neck's relative change per step
(``neck_step``) and the lag of the history's tangential slide behind the fluid
(``slide_limit``) bounded as the neck thins.

Stops at ``t_end`` or ``gap_end``, when the neck radius falls below ``neck_stop`` times its
initial value ("neck"), when a new mesh is no better ("mesh"), a solve fails ("solver",
e.g. a line receding faster than Cox-Voinov's law allows) or a pinned line's angle falls
below :data:`PIN_MIN` ("line"): the reason is in :attr:`DynamicRun.stopped`, no value is
NaN.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import quad

from wetcontact.errors import SolverError
from wetcontact.solver.meniscus import Bridge, meniscus_profile, solve_volume
from wetcontact.solver.stokes_dynamic.domain import (
    Domain,
    MeshOptions,
    contact_angles,
    correct_volume,
    dense_profile,
    lower_angle,
    on_lower,
    on_sphere,
    profile_of,
    redistribute,
    sphere_angle,
    surface_normals,
)
from wetcontact.solver.stokes_dynamic.step import (
    StepSolution,
    Wetting,
    cox_voinov,
    solve_step,
)

ORDER = 2
"""Declared order in time of the stepping (BDF2 with an extrapolated domain)."""
CURVATURE_FLOOR = 0.5
"""A new mesh's P2 map ratio may be this fraction of ``Stepping.remesh_curvature`` (below
it the run stops, reason ``"mesh"``)."""
CURVATURE_DROP = 0.8
"""A new mesh whose P2 map ratio is below ``remesh_curvature`` is remeshed when the ratio
falls to this fraction of its start."""


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
    slide_limit
        Adaptive steps: the BDF2 history's lagged tangential slide of a surface node,
        ``c dt |(u^{n+1} - u^n) . t|``, is at most this fraction of its node spacing (a
        step past it is redone shorter; ``None``: off). Near pinch the fluid's tangential
        velocity in the thread grows fast, and an unbounded lag makes the neck noisy.
    first
        The first step (backward Euler) over ``dt``; the steps then grow by ``max_ratio``.
    neck_step
        Adaptive steps: at most this relative change of the neck radius per step
        (``None``: fixed steps ``dt``, which stays the largest step); a step in which the
        neck falls by more than three times it is redone with a quarter of the step.
    max_ratio
        Largest ratio of successive steps (variable-step BDF2 is zero-stable below 2.41).
    tolerance
        Adaptive steps: the largest local error per step of the neck radius, relative to
        its initial value (``None``: off). The estimate is ``|h^{n+1} - P(t_{n+1})| / 6``,
        P the parabola through the last three accepted neck radii (for constant steps the
        difference of BDF2 and that extrapolation is (11/9) dt^3 h3, BDF2's own local
        error (2/9) dt^3 h3, h3 the neck's third derivative in time); a step past it is
        redone shorter, and the next step is at most ``0.9 (tolerance / estimate)^(1/3)``
        times the last. The neck decides where a stretched bridge breaks, and its slow
        passage past the static fold is where fixed steps lose the rupture distance.
    """

    dt: float
    t_end: float | None = None
    gap_end: float | None = None
    neck_stop: float = 0.2
    remesh_shape: float = 0.4
    remesh_curvature: float = 0.3
    max_steps: int = 100_000
    first: float = 0.125
    neck_step: float | None = None
    slide_limit: float | None = 0.1
    max_ratio: float = 1.5
    tolerance: float | None = None

    def __post_init__(self) -> None:
        if not 0.0 < self.first <= 1.0:
            raise SolverError(f"stokes-dynamic: first = {self.first!r}; allowed: (0, 1]")
        if not 1.0 <= self.max_ratio <= 2.0:
            raise SolverError(f"stokes-dynamic: max_ratio = {self.max_ratio!r}; allowed: [1, 2]")
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise SolverError(f"stokes-dynamic: dt = {self.dt!r}; allowed: finite > 0")
        if self.t_end is None and self.gap_end is None:
            raise SolverError("stokes-dynamic: give t_end or gap_end")
        if self.tolerance is not None and not (math.isfinite(self.tolerance)
                                               and 0.0 < self.tolerance < 1.0):
            raise SolverError(f"stokes-dynamic: tolerance = {self.tolerance!r}; allowed: "
                              "(0, 1)")


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
        ``"line"``, ``"max_steps"``; ``message`` has the details.
    remeshes, steps, wall_time
        Number of gmsh remeshings, time steps, and seconds.
    remesh_times
        The times of the remeshings after a step.
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
    remesh_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    diagnostics: dict[str, float] = field(default_factory=dict)


def static_profile(gap: float, volume: float, wet: Wetting, plane: str = "wall",
                   radius2: float | None = None) -> np.ndarray:
    """The static meniscus (n, 2) at ``gap`` (S/R) and ``volume`` (V/R^3), units R
    (:func:`wetcontact.solver.meniscus.solve_volume`), from the lower solid's contact line
    to the sphere's. ``plane="symmetry"``: the upper half of the bridge between two equal
    spheres at 2 gap holding 2 volume, from the mid-plane (z = 0) to the upper sphere
    (angle ``theta_sphere`` on both). ``radius2``: a lower sphere of that radius (its apex
    at the origin, angle ``theta_wall``) instead of the wall."""
    sym = plane == "symmetry"
    br = Bridge(radius=1.0, radius2=1.0 if sym else radius2,
                contact_angle1=wet.theta_sphere,
                contact_angle2=wet.theta_sphere if sym else wet.theta_wall,
                surface_tension=1.0)
    sol = solve_volume(br, 2 * gap if sym else gap, 2 * volume if sym else volume)
    if not sol.exists:
        raise SolverError(f"stokes-dynamic: no static bridge at S/R = {gap:g}, V/R^3 = "
                          f"{volume:g} ({sol.message})")
    prof = meniscus_profile(sol, n=1601 if sym else 801)
    r, z = prof["r"], prof["z"]
    if not sym:
        return np.column_stack([r, z])
    k = int(np.argmax(z > gap))  # the first point above the mid-plane
    r0 = r[k - 1] + (r[k] - r[k - 1]) * (gap - z[k - 1]) / (z[k] - z[k - 1])
    return np.vstack([[r0, 0.0], np.column_stack([r[k:], z[k:] - gap])])


def gap_history(gap0: float, speed: float | Callable[[float], float],
                gap_at: Callable[[float], float] | None = None,
                ) -> tuple[Callable[[float], float], Callable[[float], float]]:
    """S(t) and dS/dt from S(0) = gap0 and dS/dt = speed (a constant or a function of t;
    ``gap_at``: its integral S(t), when known, instead of a quadrature)."""
    if callable(speed) and gap_at is not None:
        return gap_at, speed
    if callable(speed):
        return (lambda t: gap0 + quad(speed, 0.0, t, limit=200)[0]), speed
    v = float(speed)
    return (lambda t: gap0 + v * t), (lambda t: v)


def _on_solids(xs: np.ndarray, gap: float, pinned: float | None = None,
               radius2: float | None = None) -> np.ndarray:
    """The surface with its ends put back on the lower solid (the wall, or the sphere of
    radius ``radius2``) and on the sphere at ``gap`` (at the sphere angle ``pinned`` for a
    pinned line)."""
    xs = xs.copy()
    if radius2 is None:
        xs[1, 0] = 0.0
    else:
        xs[:, 0] = on_lower(lower_angle(xs[:, :1], radius2), radius2)[:, 0]
    phi = sphere_angle(xs[:, -1:], gap) if pinned is None else np.array([pinned])
    xs[:, -1] = on_sphere(phi, gap)[:, 0]
    return xs


PIN_MIN = math.radians(2.0)
"""Smallest contact angle of a pinned line: below it the run stops (reason ``"line"``)."""
LINE_ITERATIONS = 8
"""Most solves per step with Cox-Voinov's angle, each linearised about the last's speeds."""


def _solve_lines(dom: Domain, dt: float, speed: float, wet: Wetting, intorder: int,
                 base: np.ndarray, coef: float, guess: tuple[float, float]) -> StepSolution:
    """One step; with Cox-Voinov's angle, Newton's iteration on the lines' speeds (each
    solve linearises the law about the last's) until they change by less than 1e-10 of
    themselves (or 1e-13 sigma/eta), then the law checked at them (a receding line past
    its limit stops the run)."""
    speeds = guess
    for _ in range(LINE_ITERATIONS if wet.line == "cox-voinov" else 1):
        sol = solve_step(dom, dt, speed, wet, intorder=intorder, base=base, coef=coef,
                         line_speed=speeds)
        if wet.line != "cox-voinov":
            return sol
        new = _line_speeds(sol.velocity(dom.surface), dom.surface_xy, dom.gap, speed,
                           dom.radius2)
        done = all(abs(a - b) <= 1e-13 + 1e-10 * abs(a) for a, b in zip(new, speeds,
                                                                        strict=True))
        speeds = new
        if done:
            break
    if dom.plane == "wall":
        cox_voinov(wet.theta_wall, speeds[0], wet.slip_wall, wet.macro_length)
    cox_voinov(wet.theta_sphere, speeds[1], wet.slip_sphere, wet.macro_length)
    return sol


def _line_speeds(u: np.ndarray, xs: np.ndarray, gap: float, speed: float,
                 radius2: float | None = None) -> tuple[float, float]:
    """Speeds (sigma/eta, > 0 advancing) of the lower solid's and the sphere's contact lines
    over their solids, from the velocity ``u`` (2, m) at the surface nodes ``xs``."""
    if u.size == 0:
        return 0.0, 0.0
    phi = float(sphere_angle(xs[:, -1:], gap)[0])
    a2 = 0.0 if radius2 is None else float(lower_angle(xs[:, :1], radius2)[0])
    return (float(u[0, 0] * math.cos(a2) - u[1, 0] * math.sin(a2)),
            float(u[0, -1] * math.cos(phi) + (u[1, -1] - speed) * math.sin(phi)))


def bdf_weights(omega: float | None) -> tuple[float, float, float]:
    """(a0, a1, c) of ``x^{n+1} = a0 x^n + a1 x^{n-1} + c dt w^{n+1}``: variable-step BDF2
    with ``omega = dt_n / dt_{n-1}``, or backward Euler (``omega = None``)."""
    if omega is None:
        return 1.0, 0.0, 1.0
    c = (1 + omega) / (1 + 2 * omega)
    return c * (1 + omega), -c * omega**2 / (1 + omega), c


def run(volume: float, gap0: float, speed: float | Callable[[float], float], wet: Wetting,
        stepping: Stepping, mesh: MeshOptions | None = None,
        initial: np.ndarray | None = None, intorder: int = 4,
        checkpoint: str | Path | None = None, checkpoint_every: float = 120.0,
        observer: Callable[[float, Domain, StepSolution], None] | None = None,
        gap_at: Callable[[float], float] | None = None) -> DynamicRun:
    """Follow a sphere-wall bridge of ``volume`` (V/R^3) from ``gap0`` (S/R) with the sphere
    moving at ``speed`` = dS/dt (units sigma/eta, i.e. the capillary number; > 0
    separating).

    ``initial``: the free surface (n, 2) at t = 0, from the wall's contact line to a point
    on the sphere (default: the static meniscus); its volume is corrected to ``volume``.

    ``checkpoint``: a file (``.npz``) the state is written to every ``checkpoint_every``
    seconds of wall time and at the end; a run started with an existing checkpoint of the
    same arguments resumes from it (a constant ``speed`` only). A resumed run remeshes its
    saved surface and carries the BDF2 history over as a remeshing does, so it differs
    from an uninterrupted run by the discretisation error, not more.

    ``observer(t, domain, solution)`` is called with each accepted state (the initial one
    included), e.g. to write fields at chosen gaps. ``gap_at``: S(t) of a ``speed`` given as
    a function, when its integral is known (otherwise a quadrature of the speed).
    """
    t_start = time.perf_counter()
    ckpt = None if checkpoint is None else _Checkpoint(
        Path(checkpoint), volume, gap0, speed, wet, stepping, mesh or MeshOptions(), initial)
    opts = mesh or MeshOptions()
    a2 = opts.radius2
    prof = (static_profile(gap0, volume, wet, opts.plane, a2) if initial is None
            else np.asarray(initial))
    gap_at, speed_at = gap_history(gap0, speed, gap_at)
    dom = Domain.from_profile(gap0, prof, opts)
    xs, shift = correct_volume(dom.surface_xy, gap0, volume, radius2=a2)
    if abs(shift) > 0.1 * opts.contact_size:  # a large correction: mesh the corrected shape
        dom = Domain.from_profile(gap0, profile_of(xs), opts)
        xs, _ = correct_volume(dom.surface_xy, gap0, volume, radius2=a2)
    dom = dom.moved(xs, gap0)
    neck0 = dom.neck()[0]
    pin = (float(sphere_angle(dom.surface_xy[:, -1:], gap0)[0]) if wet.line == "pinned"
           else None)
    hist: dict[str, list[float]] = {k: [] for k in ("t", "S", "F", "Fw", "neck", "V")}
    remeshes, stopped, message = 0, "", ""
    t, step = 0.0, 0
    dt, dt_prev = stepping.first * stepping.dt, math.nan
    prev: np.ndarray | None = None  # X^{n-1} at the current mesh's surface fractions
    uprev = np.zeros(0)  # the fluid's velocity at the surface nodes in the last step
    shifts: list[float] = []
    remesh_times: list[float] = []
    fresh = False  # the current mesh was just made for an inverted prediction
    curv_limit = stepping.remesh_curvature  # remesh below this P2 map ratio

    def record(t_: float, d: Domain, s: StepSolution) -> None:
        if observer is not None:
            observer(t_, d, s)
        hist["t"].append(t_)
        hist["S"].append(d.gap)
        hist["F"].append(s.force)
        hist["Fw"].append(s.force_wall)
        hist["neck"].append(d.neck()[0])
        hist["V"].append(d.volume())

    def remesh(xs_: np.ndarray, gap: float) -> Domain:
        new = Domain.from_profile(gap, dense_profile(xs_), opts)
        xs2, _ = correct_volume(new.surface_xy, gap, volume, radius2=a2)
        return new.moved(xs2, gap)

    try:  # the instantaneous flow at t = 0: the initial force
        sol = solve_step(dom, 0.0, speed_at(0.0), wet, intorder=intorder)
    except SolverError as exc:
        raise SolverError(f"stokes-dynamic: the initial solve failed: {exc}") from exc
    record(0.0, dom, sol)
    gap_prev = gap0  # the gap of ``prev``
    state = None if ckpt is None else ckpt.load()
    if state is not None:  # resume: the saved surface remeshed, its history carried over
        for k in hist:
            hist[k] = list(state[f"hist_{k}"])
        t, step, dt, dt_prev = (float(state[k]) for k in ("t", "step", "dt", "dt_prev"))
        step, neck0 = int(step), float(state["neck0"])
        remeshes, shifts = int(state["remeshes"]), list(state["shifts"])
        remesh_times = list(state["remesh_times"])
        dom = remesh(state["xs"], float(state["gap"]))
        f_new = dom.fractions["surface"]
        gap_prev = float(state["gap_prev"])
        if state["prev"].size:
            prev = _on_solids(redistribute(state["prev"], f_new), gap_prev, pin, a2)
            uprev = np.stack([np.interp(f_new, state["fractions"], uc) for uc in state["uprev"]])
        t_start -= float(state["wall_time"])
        if end := _reached(stepping, t, dom.gap, gap0, hist["neck"][-1], neck0):
            stopped, message = end
    last_save = time.perf_counter()

    def save() -> None:
        if ckpt is not None:
            ckpt.save(xs=dom.surface_xy, gap=dom.gap, fractions=dom.fractions["surface"],
                      prev=np.zeros(0) if prev is None else prev, gap_prev=gap_prev,
                      uprev=uprev, t=t, step=step, dt=dt, dt_prev=dt_prev, neck0=neck0,
                      remeshes=remeshes, shifts=np.asarray(shifts),
                      remesh_times=np.asarray(remesh_times),
                      wall_time=time.perf_counter() - t_start,
                      **{f"hist_{k}": np.asarray(v) for k, v in hist.items()})

    while not stopped:
        if ckpt is not None and time.perf_counter() - last_save > checkpoint_every:
            save()
            last_save = time.perf_counter()
        if step >= stepping.max_steps:
            stopped, message = "max_steps", f"{step} steps"
            break
        t1 = t + dt
        s1 = gap_at(t1)
        xn = dom.surface_xy
        if prev is None:  # backward Euler on the current domain (first order, one step)
            omega, star = None, xn
        else:  # BDF2 on the linear extrapolation
            omega = dt / dt_prev
            star = xn + omega * (xn - prev)
        a0, a1, c = bdf_weights(omega)
        star = _on_solids(star, s1, pin, a2)
        if np.any(star[0] <= 0):
            stopped, message = "neck", f"the predicted surface reaches the axis at t = {t1:.6g}"
            break
        dstar = dom.moved(redistribute(star, dom.fractions["surface"]), s1)
        if dstar.quality()[1] <= 0:  # the predicted mesh is inverted: remesh X^n first
            if fresh:
                stopped, message = "mesh", f"the predicted mesh at t = {t1:.6g} is inverted"
                break
            try:
                dom, prev, fresh = remesh(xn, dom.gap), None, True
                curv_limit = stepping.remesh_curvature
            except SolverError as exc:
                stopped, message = "mesh", f"remeshing at t = {t:.6g} failed: {exc}"
                break
            remeshes += 1
            continue
        try:
            base = a0 * xn
            nstar = surface_normals(dstar.surface_xy)
            if prev is not None:  # the nodes' tangential motion follows the history
                slide = (xn - prev) / dt_prev - uprev
                base = base + a1 * prev + c * dt * _tangential(slide, nstar)
            guess = (_line_speeds(uprev, xn, dom.gap, speed_at(t), a2)
                     if wet.line == "cox-voinov" else (0.0, 0.0))
            sol = _solve_lines(dstar, dt, speed_at(t1), wet, intorder, base, c, guess)
        except SolverError as exc:
            stopped, message = "solver", str(exc)
            break
        u = sol.velocity(dstar.surface)
        lag = 0.0 if prev is None else _lag(c * dt * _tangential(u - uprev, nstar), xn)
        if stepping.slide_limit is not None and lag > stepping.slide_limit:
            dt *= max(0.25, 0.9 * math.sqrt(stepping.slide_limit / lag))  # redo the step
            continue
        xs = base + c * dt * u
        xs = _on_solids(xs, s1, pin, a2)
        if np.any(xs[0] <= 0) or not np.all(np.isfinite(xs)):
            stopped, message = "neck", f"the free surface reached the axis at t = {t1:.6g}"
            break
        xs = redistribute(xs, dom.fractions["surface"])
        try:
            xs, shift = correct_volume(xs, s1, volume, radius2=a2)
            shifts.append(abs(shift))
        except SolverError as exc:
            stopped, message = "solver", str(exc)
            break
        new = dom.moved(xs, s1)
        h_new = new.neck()[0]
        can_shorten = dt > stepping.first * stepping.dt * 1e-6
        if (stepping.neck_step is not None and can_shorten
                and h_new < (1 - 3 * stepping.neck_step) * hist["neck"][-1]):
            dt *= 0.25  # the neck fell too fast: redo the step with a quarter of it
            continue
        grow = stepping.max_ratio
        if stepping.tolerance is not None and prev is not None and len(hist["t"]) >= 3:
            est = _neck_error(hist, t1, h_new) / neck0
            grow = 0.9 * (stepping.tolerance / max(est, 1e-300)) ** (1.0 / 3.0)
            if est > stepping.tolerance and can_shorten:
                dt *= max(0.25, grow)  # redo the step shorter
                continue
        prev_new, uprev = xn, u
        shape, curv = new.quality()
        if shape < stepping.remesh_shape or curv < curv_limit:
            try:
                new = remesh(xs, s1)
            except SolverError as exc:
                stopped, message = "mesh", f"remeshing at t = {t1:.6g} failed: {exc}"
                break
            remeshes += 1
            remesh_times.append(t1)
            shape, curv = new.quality()
            floor = CURVATURE_FLOOR * stepping.remesh_curvature
            if curv < floor:
                stopped, message = "mesh", (f"a new mesh at t = {t1:.6g} has a P2 map ratio "
                                            f"{curv:.3g} < {floor:.3g}")
                break
            curv_limit = (stepping.remesh_curvature if curv >= stepping.remesh_curvature
                          else CURVATURE_DROP * curv)
            # the history on the new mesh: X^n at the new surface fractions
            f_old, f_new = dom.fractions["surface"], new.fractions["surface"]
            prev_new = _on_solids(redistribute(xn, f_new), dom.gap, pin, a2)
            uprev = np.stack([np.interp(f_new, f_old, uc) for uc in u])
        gap_prev = dom.gap
        dom, prev, t, step, dt_prev, fresh = new, prev_new, t1, step + 1, dt, False
        record(t, dom, sol)
        if pin is not None and (low := min(contact_angles(dom.surface_xy, dom.gap, a2))
                                ) < PIN_MIN:
            stopped, message = "line", (
                f"a pinned line's angle fell to {math.degrees(low):.3g} deg at S/R = "
                f"{dom.gap:.6g}: the liquid wedge degenerates, and a real line depins at its "
                "receding angle (use line='cox-voinov' or 'static')")
            break
        if end := _reached(stepping, t, dom.gap, gap0, hist["neck"][-1], neck0):
            stopped, message = end
            break
        dt = min(_next_dt(stepping, hist, dt), grow * dt_prev)
        if stepping.slide_limit is not None and lag > 0:
            dt = min(dt, dt_prev * 0.9 * math.sqrt(stepping.slide_limit / lag))
        if stepping.t_end is not None:
            dt = min(dt, stepping.t_end - t)
        if dt < 1e-14 * max(1.0, t):
            stopped, message = "solver", f"time step {dt:.3g} underflows at t = {t:.6g}"
            break
    save()
    arr = {k: np.asarray(v, dtype=float) for k, v in hist.items()}
    return DynamicRun(time=arr["t"], gap=arr["S"], force=arr["F"], force_wall=arr["Fw"],
                      neck_radius=arr["neck"], volume=arr["V"], stopped=stopped,
                      message=message, remeshes=remeshes, steps=step,
                      remesh_times=np.asarray(remesh_times),
                      wall_time=time.perf_counter() - t_start, domain=dom,
                      diagnostics={"ndofs": float(sol.ndofs),
                                   "max_volume_shift": max(shifts, default=0.0),
                                   "elements": float(dom.mesh.t.shape[1])})


def _reached(stepping: Stepping, t: float, gap: float, gap0: float, r_neck: float,
             neck0: float) -> tuple[str, str] | None:
    """The stopping rule ``(reason, message)`` the state meets, or ``None``."""
    if r_neck < stepping.neck_stop * neck0:
        return "neck", (f"neck radius {r_neck:.4g} R < {stepping.neck_stop} times the "
                        f"initial {neck0:.4g} R at t = {t:.6g}")
    if stepping.t_end is not None and t >= stepping.t_end - 1e-12 * max(1.0, t):
        return "t_end", f"t = {t:.6g}"
    if (stepping.gap_end is not None and (gap - stepping.gap_end) * (gap - gap0) >= 0
            and gap != gap0):
        return "gap_end", f"S/R = {gap:.6g}"
    return None


def _tangential(v: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """The part of the nodal vectors v (2, m) along the surface (interior nodes; the ends
    have no tangential part: their whole motion is in the implicit term)."""
    out = v - np.sum(v * normals, axis=0) * normals
    out[:, 0] = out[:, -1] = 0.0
    return out


def _lag(shift: np.ndarray, xs: np.ndarray) -> float:
    """Largest tangential ``shift`` (2, m) of a surface node over the shorter of its two
    chords on the surface ``xs``."""
    chord = np.hypot(*np.diff(xs, axis=1))
    near = np.minimum(np.r_[chord, chord[-1]], np.r_[chord[0], chord])
    return float(np.max(np.hypot(*shift) / near))


def _neck_error(hist: dict[str, list[float]], t1: float, h1: float) -> float:
    """Local error estimate of a step's neck radius ``h1`` at ``t1``: a sixth of its
    distance from the parabola through the last three accepted ``(t, neck)``."""
    t, h = hist["t"][-3:], hist["neck"][-3:]
    p = 0.0
    for i in range(3):
        w = 1.0
        for j in range(3):
            if j != i:
                w *= (t1 - t[j]) / (t[i] - t[j])
        p += w * h[i]
    return abs(h1 - p) / 6.0


def _next_dt(stepping: Stepping, hist: dict[str, list[float]], dt: float) -> float:
    """The next step: ``stepping.dt``, cut so that the neck radius changes by at most
    ``stepping.neck_step`` of itself per step (at the larger of its rates over the last
    step and the last three), and grown by at most ``max_ratio``."""
    new = stepping.dt
    h, t = hist["neck"], hist["t"]
    if stepping.neck_step is not None and len(h) >= 2:
        k = max(0, len(h) - 4)
        rate = max((h[-2] - h[-1]) / (t[-1] - t[-2]), (h[k] - h[-1]) / (t[-1] - t[k]))
        if rate > 0:
            new = min(new, stepping.neck_step * h[-1] / rate)
    return min(new, stepping.max_ratio * dt)


class _Checkpoint:
    """A run's state in one ``.npz`` file, written atomically (a temporary file renamed),
    tagged with the run's arguments so that only the same run resumes from it (the stopping
    rules and gmsh's timeout aside: a finished run resumes to a later stop, and a run stopped
    by a mesh or solver failure tries the failed step again)."""

    def __init__(self, path: Path, volume: float, gap0: float, speed: object, wet: Wetting,
                 stepping: Stepping, mesh: MeshOptions, initial: np.ndarray | None) -> None:
        if callable(speed):
            raise SolverError("stokes-dynamic: checkpoint needs a constant speed (a speed "
                              "history cannot be recorded in the file)")
        self.path = path
        init = "static" if initial is None else repr(np.asarray(initial).round(15).tolist())
        steps = {k: v for k, v in asdict(stepping).items()
                 if k not in ("t_end", "gap_end", "neck_stop", "max_steps")}
        sizes = {k: v for k, v in asdict(mesh).items() if k != "timeout"}
        self.tag = repr((float(volume), float(gap0), float(speed), asdict(wet), steps,
                         sizes, init))

    def load(self) -> dict[str, np.ndarray] | None:
        """The saved state, or ``None`` when there is no file."""
        if not self.path.exists():
            return None
        with np.load(self.path, allow_pickle=False) as f:
            state = dict(f)
        if str(state.pop("tag")) != self.tag:
            raise SolverError(f"stokes-dynamic: checkpoint {self.path} was written by a run "
                              "with other arguments; delete it or give another file")
        return state

    def save(self, **state: object) -> None:
        tmp = self.path.with_name(self.path.name + ".tmp.npz")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        np.savez(tmp, tag=np.array(self.tag), **state)
        tmp.replace(self.path)
