r"""Time integration of a penetration run: the variable-step BDF2/Newton stepper with its
error control and the sphere's inertia (:func:`implicit_run`), py-pde's scipy BDF
(:func:`penetration_run`) and a Newton backward-Euler step (:func:`newton_euler_step`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pde
import scipy.sparse as sp
from scipy.integrate import BDF
from scipy.sparse.linalg import splu

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.thinfilm.forces import Snapshot, snapshot
from wetcontact.solver.thinfilm.problem import FilmProblem


class ThinFilmPDE(pde.PDEBase):
    r"""py-pde wrapper: :math:`\partial_t h = -\nabla\cdot q` of :class:`FilmProblem`."""

    explicit_time_dependence = True
    complex_valued = False
    check_implementation = False

    def __init__(self, problem: FilmProblem):
        super().__init__()
        self.problem = problem

    def evolution_rate(self, state: pde.ScalarField, t: float = 0) -> pde.ScalarField:
        """Right-hand side as a py-pde field (numpy backend)."""
        return pde.ScalarField(state.grid, self.problem.rate(state.data, t))



def _counting_bdf(counter: dict[str, int]) -> type[BDF]:
    """scipy BDF that counts accepted steps and steps shortened by rejections."""

    class CountingBDF(BDF):
        def _step_impl(self):  # noqa: ANN202 - scipy's private signature
            h_try = self.h_abs
            t_old = self.t
            ok, msg = super()._step_impl()
            if ok:
                counter["steps"] += 1
                if abs(self.t - t_old) < h_try * (1 - 1e-12):
                    counter["shortened"] += 1
            return ok, msg

    return CountingBDF


@dataclass
class RunResult:
    """Snapshots at the requested gaps, profiles, and what the integrator did."""

    snapshots: list[Snapshot]
    profiles: dict[float, np.ndarray]
    r: np.ndarray
    volume0: float
    steps: int
    steps_shortened: int
    rhs_evaluations: int
    wall_time_s: float
    speeds: list[float] = field(default_factory=list)
    reached: list[bool] = field(default_factory=list)
    min_gap: float = 0.0
    newton_iterations: int = 0
    rejected_steps: int = 0
    details: dict[float, dict[str, float]] = field(default_factory=dict)
    """Per output gap, model-specific state (the sharp contact's inner bridge)."""

    @property
    def volume_drift(self) -> float:
        """max |V(t) - V(0)|/V(0) over the output states that were reached."""
        vols = [s.volume for i, s in enumerate(self.snapshots)
                if not self.reached or self.reached[i]]
        return max(abs(v - self.volume0) for v in vols) / self.volume0


def _run_gaps(problem: FilmProblem, gaps: Sequence[float]) -> np.ndarray:
    """The output gaps of a penetration run as floats, checked: each in (0, delta], and
    the sphere approaching (velocity > 0)."""
    delta, v = problem.film_thickness, problem.velocity
    out = np.asarray(gaps, dtype=float)
    if v <= 0:
        raise InputError(f"thinfilm: velocity = {v!r}; allowed: > 0 m/s (approach)")
    if np.any(out <= 0) or np.any(out > delta * (1 + 1e-12)):
        raise InputError(f"thinfilm: gaps must lie in (0, delta = {delta:g}] m")
    return out


def penetration_run(problem: FilmProblem, gaps: Sequence[float],
                    profile_gaps: Sequence[float] = (), rtol: float = 1e-7,
                    progress: bool = False) -> RunResult:
    """Integrate from first touch (S = delta, flat film) down to min(gaps) with BDF.

    Uses py-pde's :class:`~pde.solvers.ScipySolver` (``method`` = a step-counting BDF,
    ``jac_sparsity`` pentadiagonal); outputs are taken at t = (delta - S)/v through a
    py-pde storage tracker, so the integrator lands exactly on each requested gap.

    Parameters
    ----------
    problem
        The film, sphere and grid.
    gaps
        Surface gaps S (m) at which to report, each in (0, delta].
    profile_gaps
        Gaps at which the film profile h(r) is kept (nearest output gap).
    rtol
        Relative tolerance of BDF; the absolute tolerance is rtol * min(gaps).
    progress
        Show py-pde's progress bar (tqdm).
    """
    delta, v = problem.film_thickness, problem.velocity
    gaps = _run_gaps(problem, gaps)
    order = np.argsort(-gaps)
    times = (delta - gaps[order]) / v
    times = np.maximum(times, 0.0)
    eq = ThinFilmPDE(problem)
    state = pde.ScalarField(problem.grid, delta)
    v0 = problem.volume(state.data)
    counter = {"steps": 0, "shortened": 0}
    solver = pde.ScipySolver(eq, backend="numpy", method=_counting_bdf(counter), rtol=rtol,
                             atol=rtol * float(np.min(gaps)),
                             jac_sparsity=problem.jac_sparsity())
    storage = pde.MemoryStorage()
    t_out = [t for t in times if t > 0]
    trackers: list[Any] = [storage.tracker(interrupts=t_out)] if t_out else []
    if progress:
        trackers.append("progress")
    t0 = time.perf_counter()
    info: dict[str, Any] = {}
    if t_out:
        controller = pde.Controller(solver, t_range=(0.0, float(times[-1])), tracker=trackers)
        try:
            controller.run(state)
        except (RuntimeError, ValueError) as exc:
            raise SolverError(f"thinfilm: time integration failed ({exc}); try a finer "
                              "grid, a larger penetration or a smaller rtol") from None
        info = solver.info
    wall = time.perf_counter() - t0
    stored = {float(t): np.array(d) for t, d in zip(storage.times, storage.data, strict=True)}
    snaps: list[Snapshot | None] = [None] * gaps.size
    profiles: dict[float, np.ndarray] = {}
    want = {float(gaps[np.argmin(np.abs(gaps - pg))]) for pg in profile_gaps}
    for k, idx in enumerate(order):
        t = float(times[k])
        if t == 0.0:
            h = np.full(problem.cells, delta)
        else:
            key = min(stored, key=lambda tt, t=t: abs(tt - t))
            if abs(key - t) > 1e-9 * max(t, 1e-300):
                raise SolverError(f"thinfilm: no stored state at t = {t:g} s")
            h = stored[key]
        snaps[idx] = snapshot(problem, h, float(gaps[idx]))
        if float(gaps[idx]) in want:
            profiles[float(gaps[idx])] = h.copy()
    return RunResult(snapshots=[s for s in snaps if s is not None], profiles=profiles,
                     r=problem.r_c.copy(), volume0=v0, steps=counter["steps"],
                     steps_shortened=counter["shortened"],
                     rhs_evaluations=int(info.get("steps", 0)), wall_time_s=wall)


def _banded_jacobian(rate: Callable[[np.ndarray], np.ndarray], y: np.ndarray,
                     f0: np.ndarray, film_thickness: float) -> np.ndarray:
    """Finite-difference Jacobian of ``rate`` (pentadiagonal) in LAPACK band storage (2, 2).

    Five colour groups (cells j = c mod 5 perturbed together): column j is read from rows
    j-2..j+2 of the group's difference quotient, and entry (i, j) is stored at
    ``ab[2 + i - j, j]`` as :func:`scipy.linalg.solve_banded` expects.
    """
    n = y.size
    eps = 1e-7 * np.maximum(np.abs(y), film_thickness * 1e-3)
    ab = np.zeros((5, n))
    cols = np.arange(n)
    for c in range(5):
        idx = cols[c::5]
        yp = y.copy()
        yp[idx] += eps[idx]
        dq = rate(yp) - f0
        for o in range(-2, 3):
            j = idx[(idx + o >= 0) & (idx + o < n)]
            ab[2 + o, j] = dq[j + o] / eps[j]
    return ab


def _bdf2_newton(problem: FilmProblem, rhs: np.ndarray, guess: np.ndarray, s1: float,
                 beta_dt: float, tol: float | np.ndarray,
                 maxiter: int = 10) -> tuple[np.ndarray, int]:
    """Solve y - beta_dt f(y, S1) = rhs by Newton's method on the banded Jacobian.

    Converged when every |dy_i| < tol_i (``tol`` a scalar or per cell: a small fraction
    of the local error tolerance, as in stiff integrators, so round-off in the
    finite-difference Jacobian at the contact kink cannot stall it). Returns
    (y, iterations); raises :class:`SolverError` if Newton does not converge (the caller
    then shortens the step). Every iterate keeps sum V_i y_i = sum V_i rhs_i because the
    columns of the Jacobian of a conservative flux form sum to zero.
    """
    from scipy.linalg import solve_banded

    y = guess.copy()
    # a diverging iterate (overflow, a singular Jacobian) is a failed step, not a crash:
    # the caller shortens the step
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for it in range(1, maxiter + 1):
            f0 = problem.rate_gap(y, s1)
            res = y - rhs - beta_dt * f0
            ab = -beta_dt * _banded_jacobian(lambda yy: problem.rate_gap(yy, s1), y, f0,
                                             problem.film_thickness)
            ab[2] += 1.0
            if not np.all(np.isfinite(ab)):
                break
            try:
                dy = solve_banded((2, 2), ab, -res, check_finite=False)
            except (np.linalg.LinAlgError, ValueError):
                break
            y = y + dy
            if not np.all(np.isfinite(y)):
                break
            if np.all(np.abs(dy) < tol):
                return y, it
    raise SolverError("thinfilm: Newton did not converge")


def implicit_run(problem: FilmProblem, gaps: Sequence[float],
                 profile_gaps: Sequence[float] = (), rtol: float = 1e-4,
                 mass: float | None = None, max_gap_step: float = 0.05,
                 max_steps: int = 200_000) -> RunResult:
    r"""Penetration run with an adaptive variable-step BDF2 + Newton integrator.

    From first touch (S = delta, flat film) to min(gaps). Each step solves
    :math:`h_{n+1} - a_1 h_n - a_2 h_{n-1} = \beta\,\Delta t\, f(h_{n+1}, S_{n+1})`,
    with the variable-step BDF2 coefficients (:math:`\omega = \Delta t_n/\Delta t_{n-1}`)
    :math:`a_1 = (1+\omega)^2/(1+2\omega)`, :math:`a_2 = -\omega^2/(1+2\omega)`,
    :math:`\beta = (1+\omega)/(1+2\omega)` (Hairer & Wanner, "Solving ODEs II", sec.
    III.5), backward Euler for the first step; Newton on the pentadiagonal
    finite-difference Jacobian (LAPACK banded LU). Local error estimate: the distance of
    the solution from the quadratic extrapolation of the last three states, times 2/11
    (the BDF2 error constant relative to the predictor's), in the norm
    :math:`\max_i |e_i|/(a_{tol} + r_{tol} h_i)`, :math:`a_{tol} = r_{tol}\min(gaps)`;
    the step also keeps :math:`|\Delta S| \le` ``max_gap_step`` S (the gap is the
    clock: all the stiffness is in the approach) and lands on every output gap.

    With ``mass`` = m the sphere moves under its own inertia, :math:`m\,dv/dt = -F`,
    :math:`dS/dt = -v`, v(0) = ``problem.velocity``, F the total force of
    :func:`snapshot`; coupled by a trapezoidal predictor-corrector in each step
    (S from the extrapolated speed, then v from the mean force; second order). The run
    stops when v reaches 0 (the minimum gap, interpolated) or at min(gaps); gaps never
    reached have ``reached = False``, zero forces and the state at the minimum gap.
    """
    delta, v0 = problem.film_thickness, problem.velocity
    gaps = _run_gaps(problem, gaps)
    if mass is not None and not (math.isfinite(mass) and mass > 0):
        raise InputError(f"thinfilm: mass = {mass!r}; allowed: > 0 kg or None")
    targets = sorted({float(g) for g in gaps}, reverse=True)
    s_end = targets[-1]
    atol = rtol * s_end
    newton_tol = 1e-2  # fraction of the local error tolerance
    t0w = time.perf_counter()
    h = np.full(problem.cells, delta)
    vol0 = problem.volume(h)
    hist: list[tuple[float, np.ndarray]] = [(0.0, h.copy())]
    t, s, v = 0.0, delta, v0
    f_now = snapshot(problem, h, s)
    force = f_now.force_viscous + f_now.force_capillary
    out: dict[float, tuple[Snapshot, np.ndarray, float]] = {}
    k_out = 0
    while k_out < len(targets) and targets[k_out] >= delta * (1 - 1e-12):
        # first touch: no wetted zone yet (the regularised meniscus has no force here)
        out[targets[k_out]] = (Snapshot(delta, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, vol0),
                               h.copy(), v)
        k_out += 1
    dt = 1e-4 * delta / v0
    steps = newton_total = rejected = 0
    min_gap = s_end
    stopped = False
    while k_out < len(targets):
        if steps >= max_steps:
            raise SolverError(f"thinfilm: more than {max_steps} steps; raise rtol")
        dt = min(dt, max_gap_step * s / v)
        target = targets[k_out]
        landing = s - dt * v <= target * (1 + 1e-12)
        if landing:
            dt = (s - target) / v
        # sphere: trapezoidal predictor for S_{n+1}
        if mass is None:
            s1 = target if landing else s - dt * v0
        else:
            v_pred = v - dt * force / mass
            s1 = target if landing else s - 0.5 * dt * (v + v_pred)
        if len(hist) >= 2:
            w = dt / (t - hist[-2][0])
            a1, a2, beta = (1 + w) ** 2 / (1 + 2 * w), -(w**2) / (1 + 2 * w), (1 + w) / (1 + 2 * w)
            rhs = a1 * h + a2 * hist[-2][1]
        else:
            a1, a2, beta = 1.0, 0.0, 1.0
            rhs = h
        guess = _extrapolate(hist, t + dt)
        try:
            h1, its = _bdf2_newton(problem, rhs, guess, s1, beta * dt,
                                   newton_tol * (atol + rtol * np.abs(guess)))
        except SolverError:
            rejected += 1
            dt *= 0.3
            if dt < 1e-14 * delta / v0:
                raise SolverError("thinfilm: step size underflow in the implicit "
                                  "integrator") from None
            continue
        newton_total += its
        if len(hist) >= 3:
            err = float(np.max(np.abs(h1 - guess) / (atol + rtol * np.abs(h1)))) * 2.0 / 11.0
        elif len(hist) == 2:
            err = float(np.max(np.abs(h1 - guess) / (atol + rtol * np.abs(h1)))) * 0.5
        else:
            err = 0.5
        if err > 1.0:
            rejected += 1
            dt *= max(0.2, 0.9 * err ** (-1.0 / 3.0))
            continue
        snap1 = snapshot(problem, h1, s1)
        f1 = snap1.force_viscous + snap1.force_capillary
        v_new = v0 if mass is None else v - 0.5 * dt * (force + f1) / mass
        if mass is not None and not landing:
            s1c = s - 0.5 * dt * (v + v_new)
            if v_new <= 0.0:
                # the sphere stops inside this step: the minimum gap, v(S) linear
                min_gap = s - (s - s1c) * v / (v - v_new) if v > v_new else s1c
                stopped = True
                break
        steps += 1
        hist = [*hist[-2:], (t + dt, h1)]
        t, h, s, v, force = t + dt, h1, s1, v_new, f1
        min_gap = s
        if landing:
            out[target] = (snap1, h.copy(), v)
            k_out += 1
        dt *= min(2.0, max(0.5, 0.9 * max(err, 1e-6) ** (-1.0 / 3.0)))
    wall = time.perf_counter() - t0w
    snaps: list[Snapshot] = []
    speeds: list[float] = []
    reached: list[bool] = []
    profiles: dict[float, np.ndarray] = {}
    want = {float(gaps[np.argmin(np.abs(gaps - pg))]) for pg in profile_gaps}
    for g in gaps:
        g = float(g)
        if g in out:
            sn, hh, vv = out[g]
            snaps.append(sn)
            speeds.append(vv)
            reached.append(True)
        else:
            snaps.append(Snapshot(g, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, problem.volume(h)))
            speeds.append(0.0)
            reached.append(False)
            hh = h
        if g in want:
            profiles[g] = hh.copy()
    if not stopped:
        min_gap = min(min_gap, s_end)
    return RunResult(snapshots=snaps, profiles=profiles, r=problem.r_c.copy(),
                     volume0=vol0, steps=steps, steps_shortened=rejected,
                     rhs_evaluations=newton_total * 6, wall_time_s=wall, speeds=speeds,
                     reached=reached, min_gap=float(min_gap), newton_iterations=newton_total,
                     rejected_steps=rejected)


def _extrapolate(hist: list[tuple[float, np.ndarray]], t: float) -> np.ndarray:
    """Lagrange extrapolation of the last (up to three) states to time t."""
    pts = hist[-3:]
    if len(pts) == 1:
        return pts[0][1].copy()
    out = np.zeros_like(pts[0][1])
    for i, (ti, yi) in enumerate(pts):
        li = 1.0
        for j, (tj, _) in enumerate(pts):
            if j != i:
                li *= (t - tj) / (ti - tj)
        out += li * yi
    return out


def newton_euler_step(problem: FilmProblem, h: np.ndarray, t: float, dt: float,
                      tol: float = 1e-10, maxiter: int = 30) -> np.ndarray:
    """One backward-Euler step h1 = h + dt f(h1, t + dt), solved by Newton's method.

    The Jacobian is formed by finite differences on the pentadiagonal pattern (five
    colour groups) and factorised with SuperLU. Converged when the update is below
    ``tol`` times the film thickness.

    Raises
    ------
    SolverError
        If Newton does not converge in ``maxiter`` iterations.
    """
    n = problem.cells
    t1 = t + dt
    y = h.copy()
    scale = problem.film_thickness
    for _ in range(maxiter):
        f0 = problem.rate(y, t1)
        res = y - h - dt * f0
        mat = (sp.identity(n, format="csc") - dt * _fd_jacobian(problem, y, t1, f0)).tocsc()
        dy = splu(mat).solve(-res)
        y = y + dy
        if np.max(np.abs(dy)) < tol * scale:
            return y
    raise SolverError(f"thinfilm: Newton did not converge in {maxiter} iterations "
                      f"(dt = {dt:g} s)")


def _fd_jacobian(problem: FilmProblem, y: np.ndarray, t: float,
                 f0: np.ndarray) -> sp.csc_matrix:
    """Finite-difference Jacobian of ``problem.rate`` on the pentadiagonal pattern, sparse:
    the band storage of :func:`_banded_jacobian` read as diagonals (row r holds offset
    2 - r in scipy's ``dia`` convention)."""
    ab = _banded_jacobian(lambda yy: problem.rate(yy, t), y, f0, problem.film_thickness)
    n = y.size
    return sp.dia_matrix((ab, [2, 1, 0, -1, -2]), shape=(n, n)).tocsc()

