r"""Free-film references: the leveling of a J0 mode (the declared-order check of the
model) and the largest stable time steps of the explicit and implicit integrators
(the stability study of the benchmark and the tests)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pde

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.thinfilm.integrate import ThinFilmPDE, newton_euler_step
from wetcontact.solver.thinfilm.problem import FilmProblem


def leveling_problem(cells: int, gravity: float = 0.0) -> FilmProblem:
    """A free water film, 10 um thick on a 1 mm dish (no sphere)."""
    return FilmProblem(radius=1e-3, viscosity=1e-3, surface_tension=0.072, density=998.0,
                       gravity=gravity, film_thickness=1e-5, velocity=0.0, cells=cells,
                       domain=1e-3, gap_shape="none")


def bessel_mode_decay(problem: FilmProblem, mode: int = 1, amplitude: float = 1e-4,
                      rtol: float = 1e-10) -> tuple[float, float]:
    r"""Numerical and analytic decay rate of a J0(k r) perturbation of a flat film.

    Initial h = delta (1 + a J0(k r)), k = j_{1,m}/L (J0'(kL) = 0 fits h' = 0 at L).
    Analytic rate (linear leveling, PHYSICS.md section 3):
    :math:`\gamma = \sigma\delta^3k^4/(3\eta) + \rho g\delta^3k^2/(3\eta)`.
    The numerical rate is -ln(A(t)/A(0))/t with A the projection on J0(k r), integrated
    with BDF to t = 1/(2 gamma). The problem must have ``gap_shape = "none"``.

    Returns
    -------
    (numerical, analytic) rates in 1/s.
    """
    from scipy.integrate import solve_ivp
    from scipy.special import j0, jn_zeros

    if problem.gap_shape != "none":
        raise InputError("bessel_mode_decay needs gap_shape='none' (a free film)")
    k = float(jn_zeros(1, mode)[-1]) / problem.domain
    d, eta = problem.film_thickness, problem.viscosity
    rate_an = (problem.surface_tension * d**3 * k**4 + problem.density * problem.gravity
               * d**3 * k**2) / (3.0 * eta)
    # cell averages of J0(k r) (3-point Gauss per cell), so the initial state is exact
    xg, wg = np.polynomial.legendre.leggauss(3)
    rr = 0.5 * (problem.r_f[:-1, None] + problem.r_f[1:, None]) + 0.5 * problem.dr * xg
    mode_avg = (2 * np.pi * (j0(k * rr) * rr * wg).sum(axis=1) * 0.5 * problem.dr
                / problem.vol)
    h0 = d * (1.0 + amplitude * mode_avg)

    def amp(h: np.ndarray) -> float:
        return float(np.dot(problem.vol, (h - d) * mode_avg) / np.dot(problem.vol,
                                                                         mode_avg**2))

    t_end = 0.5 / rate_an
    sol = solve_ivp(lambda t, y: problem.rate(y, t), (0.0, t_end), h0, method="BDF",
                    rtol=rtol, atol=rtol * d * amplitude * 1e-3,
                    jac_sparsity=problem.jac_sparsity(), t_eval=[t_end])
    if not sol.success:
        raise SolverError(f"thinfilm: Bessel-mode integration failed: {sol.message}")
    rate_num = -math.log(amp(sol.y[:, -1]) / amp(h0)) / t_end
    return rate_num, rate_an



def explicit_stable_dt(problem: FilmProblem, h0: np.ndarray, scheme: str = "euler",
                       steps: int = 400, lo: float = 1e-30, hi: float = 1.0,
                       t0: float = 0.0, bisections: int = 30) -> float:
    """Largest fixed dt for which py-pde's explicit Euler (or RK4) keeps the run bounded.

    Stable = after ``steps`` steps of size dt the deviation from the initial state has
    not grown beyond 10 times its initial size (and no NaN). Bisection in log dt.
    """
    eq = ThinFilmPDE(problem)
    dev0 = float(np.max(np.abs(h0 - np.mean(h0)))) + 1e-30

    def stable(dt: float) -> bool:
        state = pde.ScalarField(problem.grid, h0.copy())
        cls = pde.EulerSolver if scheme == "euler" else pde.RungeKuttaSolver
        solver = cls(eq, adaptive=False, backend="numpy")
        ctrl = pde.Controller(solver, t_range=(t0, t0 + steps * dt), tracker=None)
        try:
            with np.errstate(all="ignore"):
                final = ctrl.run(state, dt=dt)
        except (RuntimeError, FloatingPointError, ValueError):
            return False
        if final is None:
            return False
        d = final.data
        return bool(np.all(np.isfinite(d)) and np.max(np.abs(d - np.mean(h0))) < 10 * dev0)

    a, b = math.log(lo), math.log(hi)
    for _ in range(bisections):
        m = 0.5 * (a + b)
        if stable(math.exp(m)):
            a = m
        else:
            b = m
    return math.exp(a)


def implicit_stable_dt(problem: FilmProblem, h0: np.ndarray, dts: Sequence[float],
                       steps: int = 20, t0: float = 0.0) -> float:
    """Largest dt in ``dts`` for which Newton backward Euler stays bounded (and converges)."""
    dev0 = float(np.max(np.abs(h0 - np.mean(h0)))) + 1e-30
    best = 0.0
    for dt in sorted(dts):
        h = h0.copy()
        try:
            for i in range(steps):
                h = newton_euler_step(problem, h, t0 + i * dt, dt)
        except SolverError:
            break
        if not (np.all(np.isfinite(h)) and np.max(np.abs(h - np.mean(h0))) < 10 * dev0):
            break
        best = dt
    return best

