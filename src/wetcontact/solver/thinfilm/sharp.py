r"""The sharp wetting contact: a quasi-static Young-Laplace meniscus joined to the film.

The liquid under the sphere is split at the **foot** :math:`a(t)`, the minimum of the liquid
surface around the sphere (where the film's slope vanishes):

- **inner** (:math:`r < a`): a quasi-static (:math:`Ca = \eta v/\sigma \ll 1`)
  Young-Laplace surface of uniform pressure :math:`p_e` from its contact line on the sphere
  (angle :math:`\theta_s`, wetted radius :math:`r_c` an unknown) down to the foot, where it
  meets the film tangentially: the finite-element bridge of
  :mod:`wetcontact.solver.meniscus` between the sphere and the plane :math:`z = h_b` with
  contact angle 0 there, at the gap :math:`S - h_b` and pressure :math:`p_e - \rho g h_b`.
  The squeeze flow in the wetted zone gives
  :math:`F_{\rm visc} = 6\pi\eta v\int_0^{r_c}r^3/g^3dr`; the capillary force is the
  bridge's, :math:`F_{\rm cap} = \pi r_c^2 p_e - 2\pi\sigma r_c\sin(\phi_1 + \theta_s)`
  (+ the hydrostatic cap term), negative = suction.
- **outer** (:math:`a < r < L`): the small-slope thin-film equation, with
  :math:`h'(a) = 0`, :math:`p(a) = p_e`, zero flux and :math:`h' = 0` at :math:`r = L`.

The unknowns are the film cells, :math:`p_e` and :math:`a`; the two extra equations are the
foot relation :math:`a = a_{\rm bridge}(S - h_b, p_e - \rho g h_b)` and the liquid volume,
:math:`\pi a^2 h_b + V_{\rm bridge} + \int_a^L 2\pi r h\,dr = V_0`, imposed to round-off at
every step. No regularisation parameter enters. Domain: the film around the sphere has a
minimum (:math:`Ca^*` of order 1 and below), the inner meniscus is quasi-static
(:math:`Ca \ll 1`) and :math:`\theta_s < 90` deg.

Numerics: the film on a moving graded grid :math:`r = a + \xi (L - a)` in conservative
arbitrary-Lagrangian-Eulerian form, :math:`d(V_i h_i)/dt = -[A(q - w h)]_{i-1/2}^{i+1/2}`,
:math:`w = (1 - \xi)\,\dot a`; variable-step BDF2 with Newton on the bordered
pentadiagonal system, the bridge's sensitivities and tangent predictor from its own LU
factors. Accuracy: see :mod:`wetcontact.solver.thinfilm`; checks in the guide's *Solver
notes* (``docs/solvers.md``).

Sources: Oron, Davis & Bankoff (1997) Rev. Mod. Phys. 69, 931 (thin-film equation);
Donea, Huerta, Ponthot & Rodriguez-Ferran (2004), "Arbitrary Lagrangian-Eulerian methods",
Encyclopedia of Computational Mechanics, vol. 1 ch. 14; Hairer & Wanner, "Solving ODEs II",
sec. III.5 and VI.1 (variable-step BDF2, index-1 DAEs).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.linalg import solve_banded

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus.geometry import DEFAULT_ELEMENTS, Bridge
from wetcontact.solver.meniscus.guess import _guess
from wetcontact.solver.meniscus.young_laplace import (
    Fixed,
    VolumeIs,
    _admissible,
    _disc,
    _fields,
    _newton,
    _volume,
)
from wetcontact.solver.thinfilm.forces import Snapshot
from wetcontact.solver.thinfilm.integrate import RunResult, next_gap
from wetcontact.solver.thinfilm.problem import FilmPhysics, graded_faces

# ---- the inner meniscus ----------------------------------------------------------------


@dataclass(frozen=True)
class InnerState:
    """A quasi-static bridge on the plane z = h_b (SI units), with its sensitivities.

    ``gap`` is the virtual gap S - h_b, ``pressure`` the bridge's dp at its plane;
    ``foot`` its radius on the plane, ``contact_radius`` R sin(phi1) on the sphere,
    ``volume`` the liquid above the plane less the sphere below it, ``force`` the axial
    force on the sphere (positive apart). ``d*_ds``, ``d*_dp``: partial derivatives in gap
    and pressure.
    """

    gap: float
    pressure: float
    foot: float
    contact_radius: float
    filling_angle: float
    volume: float
    force: float
    dfoot_ds: float
    dfoot_dp: float
    dvol_ds: float
    dvol_dp: float
    x: np.ndarray = field(repr=False, compare=False)
    sens: np.ndarray = field(repr=False, compare=False)


class InnerMeniscus:
    """The finite-element bridge of :mod:`wetcontact.solver.meniscus` as the inner
    solution: sphere above a plane, contact angles theta_s and 0, gap of either sign.

    Parameters
    ----------
    radius, surface_tension, angle_sphere, density, gravity
        R (m), sigma (N/m), theta_s (rad), rho (kg/m^3), g (m/s^2).
    n_elements
        Elements of the bridge's meridian (order 4 in their number).
    """

    def __init__(self, radius: float, surface_tension: float, angle_sphere: float,
                 density: float = 0.0, gravity: float = 0.0,
                 n_elements: int = DEFAULT_ELEMENTS):
        self.bridge = Bridge(radius=radius, contact_angle1=angle_sphere, contact_angle2=0.0,
                             surface_tension=surface_tension, gravity=gravity,
                             density=density)
        self.ell = radius
        self.sigma = surface_tension
        self.d = _disc(int(n_elements))
        self.g = replace(self.bridge._geo(radius), immersed=True)
        self.x: np.ndarray | None = None

    def _state(self, x: np.ndarray, lu) -> InnerState:  # noqa: ANN001 - SuperLU
        d, g, ell, sig = self.d, self.g, self.ell, self.sigma
        top, _ = g.top(x[d.ic1], x[d.iS])
        cap1 = g.cap(x[d.ic1], g.rt)[0]
        cut = (2 * math.pi * top[0] * math.sin(top[2])
               - math.pi * top[0] ** 2 * (x[d.iP] - g.bo * top[1]))
        vol, dvol = _volume(d, g, x, grad=True)
        m = 3 * d.M + 6  # rows of the closings: pressure, gap
        e = np.zeros((d.m, 2))
        e[m, 0] = 1.0
        e[m + 1, 1] = 1.0
        sens = lu.solve(e)  # dx/dP, dx/dS
        ps, ls = sig / ell, ell
        return InnerState(
            gap=float(x[d.iS]) * ls, pressure=float(x[d.iP]) * ps,
            foot=float(x[d.ic2]) * ls, contact_radius=ell * math.sin(x[d.ic1]),
            filling_angle=float(x[d.ic1]), volume=float(vol) * ls**3,
            force=-(cut - g.bo * cap1) * sig * ell,
            dfoot_ds=float(sens[d.ic2, 1]), dfoot_dp=float(sens[d.ic2, 0]) * ls / ps,
            dvol_ds=float(dvol @ sens[:, 1]) * ls**2,
            dvol_dp=float(dvol @ sens[:, 0]) * ls**3 / ps, x=x.copy(), sens=sens)

    def initial(self, gap: float) -> InnerState:
        """The bridge of zero volume at virtual gap ``gap`` < 0: at first touch the
        meniscus raised above the film holds the volume of the sphere dipped below it."""
        d, g = self.d, self.g
        s = gap / self.ell
        x0 = _guess(d, g, s, V=math.pi * abs(s) ** 3)  # small beside the dipped cap
        if x0 is None:
            raise SolverError(f"thinfilm: no initial meniscus at dip {-gap:.3g} m")
        nw = _newton(d, g, x0, (VolumeIs(0.0), Fixed(d.iS, s)))
        if not nw.converged:
            raise SolverError(f"thinfilm: initial meniscus did not converge at dip {-gap:.3g} m")
        nw = _newton(d, g, nw.x, (Fixed(d.iP, float(nw.x[d.iP])), Fixed(d.iS, s)))
        self.x = nw.x
        return self._state(nw.x, nw.lu)

    def solve(self, gap: float, pressure: float,
              guess: InnerState | None = None) -> InnerState:
        """The bridge at virtual gap ``gap`` (m) and pressure ``pressure`` (Pa), by Newton
        from the tangent predictor of ``guess`` (default: the last solution)."""
        d, g = self.d, self.g
        s, p = gap / self.ell, pressure * self.ell / self.sigma
        base = guess.x if guess is not None else self.x
        x0 = base.copy()
        if guess is not None:
            pred = (guess.x + guess.sens[:, 0] * (p - guess.x[d.iP])
                    + guess.sens[:, 1] * (s - guess.x[d.iS]))
            if _admissible(d, g, pred):
                x0 = pred
        nw = _newton(d, g, x0, (Fixed(d.iP, p), Fixed(d.iS, s)))
        if not nw.converged or nw.lu is None:
            # continuation from the guess in (gap, pressure), shorter increments each time
            s0, p0 = float(base[d.iS]), float(base[d.iP])
            for k in (4, 16, 64):
                x = base
                for j in range(1, k + 1):
                    f = j / k
                    nw = _newton(d, g, x, (Fixed(d.iP, p0 + f * (p - p0)),
                                           Fixed(d.iS, s0 + f * (s - s0))))
                    if not nw.converged:
                        break
                    x = nw.x
                if nw.converged and nw.lu is not None:
                    break
        if not nw.converged or nw.lu is None:
            raise SolverError(f"thinfilm: inner meniscus did not converge (gap {gap:.3g} m, "
                              f"pressure {pressure:.4g} Pa)")
        self.x = nw.x
        return self._state(nw.x, nw.lu)

    def meridian(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(r, z) of the meridian at the vertices, from the foot to the contact line (m;
        z above the bridge's plane)."""
        r, z, _ = _fields(self.d, x)
        v = self.d.vertices
        return r[v] * self.ell, z[v] * self.ell


# ---- the outer film on the moving grid ---------------------------------------------


@dataclass(frozen=True)
class SharpFilm(FilmPhysics):
    """Parameters of a sharp-contact run (SI units): the physics of :class:`FilmPhysics`,
    the outer radius ``domain`` (m) and the sphere's contact angle ``angle_sphere`` (rad).

    ``cells`` film cells on [a, L], uniform in xi on [0, ``fine_fraction``] then growing
    by ``growth``; ``n_elements`` elements of the inner bridge.
    """

    domain: float
    angle_sphere: float
    cells: int = 200
    fine_fraction: float = 0.2
    growth: float = 1.03
    gap_shape: str = "parabolic"
    n_elements: int = DEFAULT_ELEMENTS
    xi: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.gap_shape not in ("parabolic", "sphere"):
            raise InputError(f"thinfilm: gap_shape = {self.gap_shape!r}; allowed: "
                             "'parabolic', 'sphere'")
        if not (isinstance(self.cells, int | np.integer) and self.cells >= 8):
            raise InputError(f"thinfilm: cells = {self.cells!r}; allowed: an integer >= 8")
        if not 0.0 <= self.angle_sphere < 0.5 * math.pi:
            raise InputError(f"thinfilm: contact angle on the sphere = "
                             f"{math.degrees(self.angle_sphere):.4g} deg; allowed for the "
                             "sharp wetting contact: [0, 90) deg")
        object.__setattr__(self, "xi", graded_faces(int(self.cells), 1.0, self.fine_fraction,
                                                    self.growth))

    def gap(self, r: np.ndarray | float, s: float) -> np.ndarray:
        """Gap g(r) between wall and sphere at surface gap S (m)."""
        r = np.asarray(r, dtype=float)
        if self.gap_shape == "parabolic":
            return s + r**2 / (2.0 * self.radius)
        return s + self.radius - np.sqrt(self.radius**2 - np.minimum(r, self.radius) ** 2)

    def viscous_force(self, s: float, r_c: float, v: float) -> float:
        r"""Reynolds force of the wetted zone with p = p_e at r_c:
        :math:`6\pi\eta v\int_0^{r_c} r^3/g^3\,dr` (closed form for the parabolic gap)."""
        if self.gap_shape == "parabolic":
            hh = s + r_c**2 / (2.0 * self.radius)
            return 6 * math.pi * self.viscosity * self.radius**2 * v / s * (1 - s / hh) ** 2
        from scipy.integrate import quad

        def f(r: float) -> float:
            return r**3 / float(self.gap(r, s)) ** 3

        knee = min(math.sqrt(2.0 * self.radius * s), r_c)  # where the gap has doubled
        val = (quad(f, 0.0, knee, epsabs=0.0, epsrel=1e-11, limit=200)[0]
               + quad(f, knee, r_c, epsabs=0.0, epsrel=1e-11, limit=200)[0])
        return 6 * math.pi * self.viscosity * v * val

    def geometry(self, a: float) -> dict[str, np.ndarray]:
        """Faces, centres, cell volumes, face areas, centre spacing, dV/da of the grid
        r = a + xi (L - a)."""
        r_f = a + self.xi * (self.domain - a)
        r_c = 0.5 * (r_f[1:] + r_f[:-1])
        dr_da = 1.0 - self.xi
        return {"r_f": r_f, "r_c": r_c, "vol": np.pi * (r_f[1:] ** 2 - r_f[:-1] ** 2),
                "area": 2.0 * np.pi * r_f, "dc": np.diff(r_c),
                "dvol_da": 2.0 * np.pi * (r_f[1:] * dr_da[1:] - r_f[:-1] * dr_da[:-1])}

    @staticmethod
    def foot_height(h: np.ndarray) -> float:
        r"""Film height at the foot: the first cell's value (h' = 0 at the foot, so it
        differs from h(a) by :math:`h''\Delta^2/2`, second order in the cell width)."""
        return float(h[0])

    def rate(self, h: np.ndarray, p_e: float, a: float, adot: float) -> np.ndarray:
        r"""ALE rate :math:`d(V_i h_i)/dt = -[A(q - w h)]` of the film cells (m^3/s)."""
        geo = self.geometry(a)
        area, dc, vol = geo["area"], geo["dc"], geo["vol"]
        n = self.cells
        grad = np.zeros(n + 1)
        grad[1:-1] = np.diff(h) / dc
        lap = np.diff(area * grad) / vol
        p = -self.surface_tension * lap + self.density * self.gravity * h
        h_b = self.foot_height(h)
        flux = np.zeros(n + 1)
        hf = 0.5 * (h[1:] + h[:-1])
        w = (1.0 - self.xi) * adot
        flux[1:-1] = (-hf**3 / (3.0 * self.viscosity) * np.diff(p) / dc - w[1:-1] * hf)
        dlt = geo["r_c"][0] - a
        flux[0] = -h_b**3 / (3.0 * self.viscosity) * (p[0] - p_e) / dlt - w[0] * h_b
        return -np.diff(area * flux)

    def film_volume(self, h: np.ndarray, a: float) -> float:
        """Liquid volume of the film on [a, L] (m^3)."""
        return float(np.dot(self.geometry(a)["vol"], h))


# ---- time integration -----------------------------------------------------------------


@dataclass
class _Step:
    """Accepted state: time, film, edge pressure, foot, inner bridge, gap, speed."""

    t: float
    h: np.ndarray
    p_e: float
    a: float
    inner: InnerState
    s: float
    v: float


def _snapshot(prob: SharpFilm, st: _Step) -> Snapshot:
    """Forces and geometry of an accepted state (Snapshot fields of :mod:`.forces`:
    wetted radius = the contact radius on the sphere, edge pressure = p_e)."""
    r_c = st.inner.contact_radius
    f_visc = prob.viscous_force(st.s, r_c, st.v if st.v > 0 else 0.0)
    geo = prob.geometry(st.a)
    slope = float(np.max(np.abs(np.diff(st.h) / geo["dc"]))) if prob.cells > 1 else 0.0
    h_b = prob.foot_height(st.h)
    vol = math.pi * st.a**2 * h_b + st.inner.volume + prob.film_volume(st.h, st.a)
    return Snapshot(st.s, f_visc, st.inner.force, r_c, st.p_e, slope, 0.0, vol)


def _newton_step(prob: SharpFilm, inner: InnerMeniscus, s1: float, dt_beta: float,
                 rhs_u: np.ndarray, rhs_a: float, guess: tuple[np.ndarray, float, float],
                 vol0: float, tol_h: np.ndarray, tol_p: float, tol_a: float,
                 inner_guess: InnerState, maxiter: int = 12
                 ) -> tuple[np.ndarray, float, float, InnerState, int]:
    """Solve the BDF2 system of one step by damped Newton: film rows
    V_i(a) h_i - rhs_u_i - beta dt rate_i(h, p_e, a, adot) = 0,
    adot = (a - rhs_a)/(beta dt); the liquid volume; the foot relation. The update is
    damped so that p_e changes by at most half its size (the bridge must stay solvable);
    converged when a full step is below the tolerances and the volume is exact to 1e-12."""
    h, p_e, a = guess[0].copy(), float(guess[1]), float(guess[2])
    n = prob.cells
    rho_g = prob.density * prob.gravity
    p_scale = prob.surface_tension / prob.radius
    st = inner.solve(s1 - h[0], p_e - rho_g * h[0], guess=inner_guess)

    def film_res(hh: np.ndarray, pe: float, aa: float) -> np.ndarray:
        geo = prob.geometry(aa)
        adot = (aa - rhs_a) / dt_beta
        return (geo["vol"] * hh - rhs_u - dt_beta * prob.rate(hh, pe, aa, adot)) / geo["vol"]

    cols = np.arange(n)
    for it in range(1, maxiter + 1):
        h_b = h[0]
        f0 = film_res(h, p_e, a)
        geo = prob.geometry(a)
        c_res = math.pi * a**2 * h_b + st.volume + float(np.dot(geo["vol"], h)) - vol0
        a_res = a - st.foot
        # banded Jacobian of the film rows in h (5 colours), columns p_e and a by differences
        eps_h = 1e-7 * np.maximum(np.abs(h), prob.film_thickness * 1e-3)
        ab = np.zeros((5, n))
        for c in range(5):
            idx = cols[c::5]
            hp = h.copy()
            hp[idx] += eps_h[idx]
            dq = film_res(hp, p_e, a) - f0
            for o in range(-2, 3):
                j = idx[(idx + o >= 0) & (idx + o < n)]
                ab[2 + o, j] = dq[j + o] / eps_h[j]
        eps_p = 1e-7 * max(abs(p_e), p_scale)
        col_p = (film_res(h, p_e + eps_p, a) - f0) / eps_p
        eps_a = 1e-7 * a
        col_a = (film_res(h, p_e, a + eps_a) - f0) / eps_a
        # analytic rows: volume and foot (chain rule through h_b = h_0 and the bridge at
        # gap S - h_b, pressure p_e - rho g h_b)
        dv_dhb = -(st.dvol_ds + rho_g * st.dvol_dp)
        df_dhb = -(st.dfoot_ds + rho_g * st.dfoot_dp)
        row_c = geo["vol"].copy()
        row_c[0] += math.pi * a**2 + dv_dhb
        c_p = st.dvol_dp
        c_a = 2 * math.pi * a * h_b + float(np.dot(geo["dvol_da"], h))
        f_h0, f_p, f_a = -df_dhb, -st.dfoot_dp, 1.0
        # bordered solve: B X = [col_p, col_a, -f0]; Schur complement on (p_e, a)
        rhs = np.column_stack((col_p, col_a, -f0))
        try:
            xx = solve_banded((2, 2), ab, rhs, check_finite=True)
        except (np.linalg.LinAlgError, ValueError):
            raise SolverError("thinfilm: singular film Jacobian") from None
        e11 = c_p - row_c @ xx[:, 0]
        e12 = c_a - row_c @ xx[:, 1]
        e21 = f_p - f_h0 * xx[0, 0]
        e22 = f_a - f_h0 * xx[0, 1]
        r1 = -c_res - row_c @ xx[:, 2]
        r2 = -a_res - f_h0 * xx[0, 2]
        det = e11 * e22 - e12 * e21
        if not (math.isfinite(det) and det != 0.0):
            raise SolverError("thinfilm: singular bordered system")
        dp = (r1 * e22 - e12 * r2) / det
        da = (e11 * r2 - e21 * r1) / det
        dh = xx[:, 2] - xx[:, 0] * dp - xx[:, 1] * da
        if not (np.all(np.isfinite(dh)) and math.isfinite(dp) and math.isfinite(da)):
            raise SolverError("thinfilm: Newton diverged")
        lam = min(1.0, 0.5 * max(abs(p_e), p_scale) / max(abs(dp), 1e-300),
                  0.2 * a / max(abs(da), 1e-300))
        while True:
            hn, pn, an = h + lam * dh, p_e + lam * dp, a + lam * da
            if 0.0 < an < prob.domain and np.min(hn) > 0.0:
                try:
                    stn = inner.solve(s1 - hn[0], pn - rho_g * hn[0], guess=st)
                    break
                except SolverError:
                    pass
            lam *= 0.5
            if lam < 1e-3:
                raise SolverError("thinfilm: damped Newton stalled")
        h, p_e, a, st = hn, pn, an, stn
        if (lam == 1.0 and np.all(np.abs(dh) < tol_h) and abs(dp) < tol_p
                and abs(da) < tol_a):
            geo = prob.geometry(a)
            c_res = math.pi * a**2 * h[0] + st.volume + float(np.dot(geo["vol"], h)) - vol0
            if abs(c_res) < 1e-12 * vol0 and abs(a - st.foot) < 1e-9 * a:
                return h, p_e, a, st, it
    raise SolverError("thinfilm: Newton did not converge")


def sharp_run(prob: SharpFilm, gaps: Sequence[float], profile_gaps: Sequence[float] = (),
              rtol: float = 1e-4, mass: float | None = None, max_gap_step: float = 0.05,
              max_steps: int = 100_000, first_dip: float = 1e-2) -> RunResult:
    r"""Penetration run of the sharp contact from first touch to min(gaps).

    Starts at :math:`S_0 = \delta(1 -` ``first_dip``:math:`)` from the flat film with the
    zero-volume bridge (the meniscus raised above the film holds the volume of the sphere
    dipped below it); at S = delta the force is 0 (first touch), output gaps in
    :math:`(S_0, \delta)` are such quasi-static initial states. Then variable-step BDF2
    (Hairer & Wanner, sec. III.5) with the local error of the film, the foot and the edge
    pressure against the quadratic predictor (x 2/11), :math:`|\Delta S| \le`
    ``max_gap_step`` S, landing on each output gap. ``mass``: the sphere moves under its
    inertia (trapezoidal predictor-corrector as :func:`~.integrate.implicit_run`).
    """
    delta, v0 = prob.film_thickness, prob.velocity
    gaps = np.asarray(gaps, dtype=float)
    if not v0 > 0:
        raise InputError(f"thinfilm: velocity = {v0!r}; allowed: > 0 m/s (approach)")
    if np.any(gaps <= 0) or np.any(gaps > delta * (1 + 1e-12)):
        raise InputError(f"thinfilm: gaps must lie in (0, delta = {delta:g}] m")
    if mass is not None and not (math.isfinite(mass) and mass > 0):
        raise InputError(f"thinfilm: mass = {mass!r}; allowed: > 0 kg or None")
    t_wall = time.perf_counter()
    targets = sorted({float(g) for g in gaps}, reverse=True)
    s_end = targets[-1]
    atol = rtol * delta
    rho_g = prob.density * prob.gravity
    inner = InnerMeniscus(prob.radius, prob.surface_tension, prob.angle_sphere,
                          prob.density, prob.gravity, prob.n_elements)
    vol0 = math.pi * prob.domain**2 * delta
    out: dict[float, tuple[Snapshot, _Step]] = {}

    def initial(s: float) -> _Step:
        st = inner.initial(s - delta)
        h = np.full(prob.cells, delta)
        p_e = st.pressure + rho_g * delta
        return _Step(0.0, h, p_e, st.foot, st, s, v0)

    s0 = delta * (1.0 - first_dip)
    k_out = 0
    while k_out < len(targets) and targets[k_out] > s0:
        g = targets[k_out]
        if g >= delta * (1 - 1e-12):
            out[g] = (Snapshot(delta, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, vol0), None)  # type: ignore[assignment]
        else:
            st0 = initial(g)
            out[g] = (_snapshot(prob, st0), st0)
        k_out += 1
    cur = initial(s0)
    cur.t = (delta - s0) / v0
    hist: list[_Step] = [cur]
    force = _snapshot(prob, cur)
    f_now = force.force_viscous + force.force_capillary
    dt = 1e-3 * delta / v0
    steps = newton_total = rejected = 0
    min_gap, stopped = s_end, False
    while k_out < len(targets):
        if steps >= max_steps:
            raise SolverError(f"thinfilm: more than {max_steps} steps; raise rtol")
        s, v = cur.s, cur.v
        target = targets[k_out]
        dt, s1, landing = next_gap(s, v, v0, dt, target, max_gap_step, mass, f_now)
        geo_n = prob.geometry(cur.a)
        u_n = geo_n["vol"] * cur.h
        if len(hist) >= 2:
            prev = hist[-2]
            w = dt / (cur.t - prev.t)
            a1, a2, beta = (1 + w) ** 2 / (1 + 2 * w), -(w**2) / (1 + 2 * w), (1 + w) / (1 + 2 * w)
            rhs_u = a1 * u_n + a2 * prob.geometry(prev.a)["vol"] * prev.h
            rhs_a = a1 * cur.a + a2 * prev.a
        else:
            beta, rhs_u, rhs_a = 1.0, u_n, cur.a
        pred = _extrapolate(hist, cur.t + dt)
        tol_h = 1e-2 * (atol + rtol * np.abs(pred[0]))
        tol_p = 1e-2 * rtol * max(abs(pred[1]), prob.surface_tension / prob.radius)
        tol_a = 1e-2 * rtol * pred[2]
        try:
            h1, p1, a1_, st1, its = _newton_step(prob, inner, s1, beta * dt, rhs_u, rhs_a,
                                                 pred, vol0, tol_h, tol_p, tol_a, cur.inner)
        except SolverError:
            rejected += 1
            dt *= 0.3
            if dt < 1e-14 * delta / v0:
                raise SolverError("thinfilm: step size underflow (sharp contact)") from None
            continue
        newton_total += its
        err_v = max(float(np.max(np.abs(h1 - pred[0]) / (atol + rtol * np.abs(h1)))),
                    abs(a1_ - pred[2]) / (rtol * a1_),
                    abs(p1 - pred[1]) / (rtol * max(abs(p1), 1e-300)))
        err = err_v * (2.0 / 11.0 if len(hist) >= 3 else 0.5)
        if len(hist) < 2:
            err = 0.5
        if err > 1.0:
            rejected += 1
            dt *= max(0.2, 0.9 * err ** (-1.0 / 3.0))
            continue
        new = _Step(cur.t + dt, h1, p1, a1_, st1, s1, v0)
        snap = _snapshot(prob, new)
        f1 = snap.force_viscous + snap.force_capillary
        if mass is not None:
            v_new = v - 0.5 * dt * (f_now + f1) / mass
            if not landing:
                s1c = s - 0.5 * dt * (v + v_new)
                if v_new <= 0.0:
                    min_gap = s - (s - s1c) * v / (v - v_new) if v > v_new else s1c
                    stopped = True
                    break
            new.v = v_new
            snap = _snapshot(prob, new)
            f1 = snap.force_viscous + snap.force_capillary
        steps += 1
        hist = [*hist[-2:], new]
        cur, f_now = new, f1
        min_gap = cur.s
        if landing:
            out[target] = (snap, cur)
            k_out += 1
        dt *= min(2.0, max(0.5, 0.9 * max(err, 1e-6) ** (-1.0 / 3.0)))
    wall = time.perf_counter() - t_wall
    snaps, speeds, reached = [], [], []
    profiles: dict[float, np.ndarray] = {}
    details: dict[float, dict[str, float]] = {}
    r_out = np.linspace(0.0, prob.domain, 400)
    want = {float(gaps[np.argmin(np.abs(gaps - pg))]) for pg in profile_gaps}
    for g in gaps:
        g = float(g)
        if g in out:
            sn, st = out[g]
            snaps.append(sn)
            if st is not None:
                details[g] = {"foot_radius": st.a, "foot_height": float(st.h[0]),
                              "virtual_gap": st.inner.gap,
                              "bridge_pressure": st.inner.pressure,
                              "bridge_volume": st.inner.volume,
                              "filling_angle": st.inner.filling_angle}
            speeds.append(st.v if st is not None else v0)
            reached.append(True)
        else:
            st = cur
            snaps.append(Snapshot(g, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, sn.volume if snaps else vol0))
            speeds.append(0.0)
            reached.append(False)
        if g in want:
            profiles[g] = (_profile(prob, inner, st, r_out) if st is not None
                           else np.full(r_out.size, delta))
    if not stopped:
        min_gap = min(min_gap, s_end)
    return RunResult(snapshots=snaps, profiles=profiles, r=r_out, volume0=vol0, steps=steps,
                     steps_shortened=rejected, rhs_evaluations=newton_total * 8,
                     wall_time_s=wall, speeds=speeds, reached=reached,
                     min_gap=float(min_gap), newton_iterations=newton_total,
                     rejected_steps=rejected, details=details)


def _extrapolate(hist: list[_Step], t: float) -> tuple[np.ndarray, float, float]:
    """Lagrange extrapolation of (h, p_e, a) of the last (up to three) states to time t."""
    pts = hist[-3:]
    hh = np.zeros_like(pts[0].h)
    pe = aa = 0.0
    for i, st in enumerate(pts):
        li = 1.0
        for j, sj in enumerate(pts):
            if j != i:
                li *= (t - sj.t) / (st.t - sj.t)
        hh += li * st.h
        pe += li * st.p_e
        aa += li * st.a
    return hh, pe, aa


def _profile(prob: SharpFilm, inner: InnerMeniscus, st: _Step, r_out: np.ndarray) -> np.ndarray:
    """Liquid surface on ``r_out``: the gap inside the contact line, the meniscus (its
    outer envelope where it overhangs), the film beyond the foot."""
    r_c, a = st.inner.contact_radius, st.a
    h_b = prob.foot_height(st.h)
    rm, zm = inner.meridian(st.inner.x)
    zm = zm + h_b
    order = np.argsort(rm)
    geo = prob.geometry(a)
    out = np.interp(r_out, np.concatenate(([a], geo["r_c"])), np.concatenate(([h_b], st.h)))
    mid = (r_out >= r_c) & (r_out < a)
    out[mid] = np.interp(r_out[mid], rm[order], zm[order])
    inside = r_out < r_c
    out[inside] = prob.gap(r_out[inside], st.s)
    return out
