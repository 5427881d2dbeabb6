"""Level 1: the axisymmetric Reynolds equation for a finite amount of liquid.

The quasi-steady thin-gap (lubrication) pressure p(r) in the wetted disk 0 <= r <= r_w
solves (Reynolds 1886; axisymmetric squeeze form e.g. Hamrock, *Fundamentals of Fluid Film
Lubrication*, ch. 7)::

    (1/r) d/dr ( r M(h) dp/dr ) = dh/dt = -v,      p'(0) = 0,  p(r_w) = p_b,

with the approach speed v (positive = approach; the relative speed -dS/dt for two spheres)
and the Navier-slip mobility (slip lengths b1, b2 on the two surfaces)::

    M(h) = h^3/(12 eta) * (h^2 + 4 h (b1 + b2) + 12 b1 b2) / (h (h + b1 + b2)),

which gives Vinogradova's (1995) slip factors for a parabolic gap. The axial force on the
sphere (positive = pushing the surfaces apart) is ``int_0^{r_w} 2 pi r p dr``; it is split
into the viscous part ``int 2 pi r (p - p_b) dr`` and the boundary-pressure part
``pi r_w^2 p_b`` (the Laplace suction of the wetted zone when p_b < 0).

Separation (v < 0) lowers the pressure; a cavitation floor p >= p_cav turns the problem into
an obstacle problem (Swift-Stieber conditions p = p_cav, p' = 0 at the cavitation front),
solved by a primal-dual active-set iteration on the discrete system.

Discretisation
--------------
With xi = r^2 the equation reads ``4 d/dxi (xi M dp/dxi) = -v``. The computational coordinate
s in [0, 1] is uniform and maps to xi through the gap itself: ``ln h`` is uniform in s for the
sphere-wall and parabolic gaps (so the mesh is graded on the scale r ~ sqrt(R S) near the
axis and geometrically coarser outward), and ``ln(1 + xi/(2 R* S))`` is uniform for two
spheres and for a tabulated gap. A vertex-centred finite-volume scheme (fluxes at the cell
faces, exact cell integrals of the source, trapezoidal force) is second order with an error
expansion in even powers of the cell size, so Richardson extrapolation over ``levels``
meshes of n, 2n, 4n cells raises the order to 2 * levels. Every gap of a curve uses the same
reference mesh in s; the tridiagonal systems of all gaps are stacked into one banded system
and solved at once (LAPACK through :func:`scipy.linalg.solve_banded`).

Validity: thin gap (|dh/dr| small over the wetted zone). The model refuses immersed scenes,
wetted radii beyond the equator of a sphere and wetted zones where the sphere's surface is
steeper than 60 degrees (r_w > (sqrt 3/2) R_min); use ``stokes`` there.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, ClassVar, Literal

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.linalg import solve_banded

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.reduced_models.viscous import past_rupture_note
from wetcontact.scene import Scene

NAME = "lubrication"
#: Largest wetted xi = r_w^2 accepted, as a fraction of R_min^2: sphere surface slope <= 60 deg.
MAX_XI_FRACTION = 0.75
#: Default cavitation pressure relative to ambient (Pa): absolute zero under 1 atm.
P_CAV_DEFAULT = -101325.0
#: Largest number of active-set iterations before the obstacle solve is declared failed.
MAX_ACTIVE_SET_ITER = 200

Shape = Literal["sphere-wall", "sphere-sphere", "parabolic", "tabulated"]


# ---- physics as small functions --------------------------------------------------------


def slip_mobility(h: np.ndarray, eta: float, b1: float = 0.0, b2: float = 0.0) -> np.ndarray:
    """Flux mobility of a thin gap with Navier slip on both surfaces.

    ``q = -M dp/dr`` per unit circumference with::

        M = h^3/(12 eta) * (h^2 + 4 h (b1 + b2) + 12 b1 b2) / (h (h + b1 + b2))

    (plane Poiseuille flow with Navier conditions u = b1 u' and u = -b2 u' on the walls;
    b1 = b2 = b gives 1 + 6 b/h, b2 = 0 gives (h + 4 b1)/(h + b1), Vinogradova 1995).

    Parameters
    ----------
    h
        Local gap (m), > 0.
    eta
        Viscosity (Pa s).
    b1, b2
        Slip lengths (m), >= 0.
    """
    h = np.asarray(h, dtype=float)
    if b1 == 0.0 and b2 == 0.0:
        return h**3 / (12.0 * eta)
    return h**2 * (h * h + 4.0 * h * (b1 + b2) + 12.0 * b1 * b2) / (12.0 * eta * (h + b1 + b2))


def sphere_rise(xi: np.ndarray, radius: float) -> np.ndarray:
    """Height of a sphere's surface above its lowest point at r^2 = xi: ``R - sqrt(R^2 - xi)``.

    Written ``xi / (R + sqrt(R^2 - xi))`` to avoid cancellation near the axis.
    """
    return xi / (radius + np.sqrt(np.maximum(radius * radius - xi, 0.0)))


def _sphere_volume_term(xi: np.ndarray, radius: float) -> np.ndarray:
    """``int_0^xi (R - sqrt(R^2 - x)) dx = xi^2 (R + 2c) / (3 (R + c)^2)``, c = sqrt(R^2 - xi)."""
    c = np.sqrt(np.maximum(radius * radius - xi, 0.0))
    return xi * xi * (radius + 2.0 * c) / (3.0 * (radius + c) ** 2)


# ---- gap profiles ------------------------------------------------------------------------


@dataclass(frozen=True)
class GapProfile:
    """An axisymmetric gap h(r) between two surfaces, smallest at the axis (h(0) = S).

    Build with the class methods :meth:`sphere_wall`, :meth:`sphere_sphere`,
    :meth:`parabolic` or :meth:`tabulated`. Vectorised over the gap S (an array of gaps
    shares the shape and radii: one force curve).

    Attributes
    ----------
    shape
        ``"sphere-wall"`` (h = S + R - sqrt(R^2 - r^2)), ``"sphere-sphere"`` (both caps),
        ``"parabolic"`` (h = S + r^2/(2 R)) or ``"tabulated"`` (a given h(r)).
    gap
        S = h(0) (m), shape (G,).
    radius, radius2
        Sphere radii (m); for ``"parabolic"`` ``radius`` is the curvature radius R*.
    table
        For ``"tabulated"``: a cubic spline of h against xi = r^2, and its xi range.
    """

    shape: Shape
    gap: np.ndarray
    radius: float
    radius2: float | None = None
    table: CubicSpline | None = None
    xi_max: float = math.inf

    # -- constructors
    @classmethod
    def sphere_wall(cls, gap: Any, radius: float) -> GapProfile:
        """Exact gap of a sphere of radius R above a plane wall."""
        return cls("sphere-wall", _gaps(gap), _pos("radius", radius))

    @classmethod
    def sphere_sphere(cls, gap: Any, radius: float, radius2: float) -> GapProfile:
        """Exact gap between two spheres of radii R1, R2 on a common axis."""
        return cls("sphere-sphere", _gaps(gap), _pos("radius", radius), _pos("radius2", radius2))

    @classmethod
    def parabolic(cls, gap: Any, radius: float) -> GapProfile:
        """Parabolic gap ``h = S + r^2/(2 R)`` (R = R* for two spheres)."""
        return cls("parabolic", _gaps(gap), _pos("radius", radius))

    @classmethod
    def tabulated(cls, r: Any, h: Any) -> GapProfile:
        """A given gap h(r) (m) on increasing radii r (m) starting at r = 0.

        The hook for deformed surfaces: h is interpolated by a cubic spline in xi = r^2
        (smooth for smooth axisymmetric surfaces). The mesh is graded on the scale
        xi ~ 2 R_c h(0) with R_c = 1/(2 h''(0)) estimated from the spline.
        """
        r = np.asarray(r, dtype=float)
        h = np.asarray(h, dtype=float)
        if r.ndim != 1 or r.shape != h.shape or r.size < 4:
            raise InputError("tabulated gap: r and h must be 1-D arrays of the same length >= 4")
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(h))):
            raise InputError("tabulated gap: r and h must be finite")
        if r[0] != 0.0 or np.any(np.diff(r) <= 0):
            raise InputError("tabulated gap: r must start at 0 and increase strictly")
        _check_positive_gap(r, h)
        spline = CubicSpline(r * r, h)
        slope = float(spline(0.0, 1))
        rc = 1.0 / (2.0 * slope) if slope > 0 else math.inf
        return cls("tabulated", np.array([h[0]]), rc, table=spline, xi_max=float(r[-1] ** 2))

    # -- geometry
    @property
    def reduced_radius(self) -> float:
        """R_c, the curvature radius of the gap at the axis (R, R1 R2/(R1 + R2), or R)."""
        if self.shape == "sphere-sphere":
            assert self.radius2 is not None
            return self.radius * self.radius2 / (self.radius + self.radius2)
        return self.radius

    @property
    def equator_xi(self) -> float:
        """xi = r^2 at the equator of the smaller sphere (inf for a parabola)."""
        if self.shape in ("sphere-wall", "sphere-sphere"):
            return min(self.radius, self.radius2 or self.radius) ** 2
        return self.xi_max

    def h_of_xi(self, xi: np.ndarray, gap: np.ndarray | None = None) -> np.ndarray:
        """Gap h at xi = r^2 (m); ``gap`` broadcasts against ``xi`` (default: self.gap)."""
        s = self.gap if gap is None else gap
        if self.shape == "sphere-wall":
            return s + sphere_rise(xi, self.radius)
        if self.shape == "sphere-sphere":
            assert self.radius2 is not None
            return s + sphere_rise(xi, self.radius) + sphere_rise(xi, self.radius2)
        if self.shape == "parabolic":
            return s + xi / (2.0 * self.radius)
        assert self.table is not None
        return np.asarray(self.table(xi), dtype=float)

    def h(self, r: Any) -> np.ndarray:
        """Gap h(r) (m) for the first (or only) S."""
        r = np.asarray(r, dtype=float)
        return self.h_of_xi(r * r, self.gap[0])

    def xi_of_edge_gap(self, edge_gap: np.ndarray) -> np.ndarray:
        """xi_w with h(xi_w) = H (a film of thickness H on the wall): closed forms."""
        rise = edge_gap - self.gap
        if self.shape == "sphere-wall":
            return rise * (2.0 * self.radius - rise)
        if self.shape == "parabolic":
            return 2.0 * self.radius * rise
        raise InputError(f"a film edge gap needs a sphere-wall or parabolic gap, not {self.shape}")

    def volume_between(self, xi: np.ndarray) -> np.ndarray:
        """Liquid volume between the surfaces inside r^2 <= xi: ``pi int_0^xi h dxi`` (m^3)."""
        if self.shape == "parabolic":
            return np.pi * (self.gap * xi + xi * xi / (4.0 * self.radius))
        if self.shape == "sphere-wall":
            return np.pi * (self.gap * xi + _sphere_volume_term(xi, self.radius))
        if self.shape == "sphere-sphere":
            assert self.radius2 is not None
            return np.pi * (self.gap * xi + _sphere_volume_term(xi, self.radius)
                            + _sphere_volume_term(xi, self.radius2))
        raise InputError("bridge volumes are not implemented for a tabulated gap; give r_w")

    def xi_of_volume(self, volume: np.ndarray) -> np.ndarray:
        """xi_w whose disk holds the liquid volume V between the surfaces (Newton, convex)."""
        rc = self.reduced_radius
        s = self.gap
        v = np.broadcast_to(np.asarray(volume, dtype=float), s.shape)
        a = v / (np.pi * rc)
        rise = a / (np.sqrt(s * s + a) + s)           # H - S of the parabolic bridge
        xi = np.minimum(2.0 * rc * rise, self.equator_xi)
        if self.shape == "parabolic":
            return xi
        for _ in range(60):                           # G convex: Newton descends monotonically
            step = (self.volume_between(xi) - v) / (np.pi * self.h_of_xi(xi, s))
            xi = xi - step
            if np.all(np.abs(step) <= 1e-15 * xi):
                break
        return xi


def _gaps(gap: Any) -> np.ndarray:
    g = np.atleast_1d(np.asarray(gap, dtype=float))
    if g.ndim != 1 or not np.all(np.isfinite(g)):
        raise InputError(f"gap = {gap!r}; allowed: finite numbers > 0 m")
    if np.any(g <= 0):
        raise ValidityError(NAME, f"gap S = {g[g <= 0][0]!r} m <= 0: the surfaces touch or "
                            "overlap, a dry-contact law (Hertz/JKR) applies, not lubrication")
    return g


def _pos(name: str, x: Any) -> float:
    x = float(x)
    if not (math.isfinite(x) and x > 0):
        raise InputError(f"{name} = {x!r}; allowed: a finite number > 0")
    return x


def _check_positive_gap(r: np.ndarray, h: np.ndarray) -> None:
    if np.any(h <= 0):
        i = int(np.argmax(h <= 0))
        raise ValidityError(NAME, f"gap h(r) = {h[i]:.6g} m <= 0 at r = {r[i]:.6g} m: the "
                            "surfaces touch or overlap, a dry-contact law (Hertz/JKR) applies, "
                            "not lubrication")


# ---- the finite-volume solver ----------------------------------------------------------


@dataclass(frozen=True)
class ReynoldsSolution:
    """Result of :func:`solve_reynolds` (arrays over the gaps of the profile).

    Attributes
    ----------
    force_viscous
        ``int_0^{r_w} 2 pi r (p - p_b) dr`` (N), Richardson-extrapolated.
    force_boundary
        ``pi r_w^2 p_b`` (N): the boundary (Laplace) pressure acting on the wetted disk.
    wetted_radius, edge_gap
        r_w (m) and H = h(r_w) (m).
    cavitation_radius
        Radius of the cavitated disk (m), 0 where the film does not cavitate.
    error_estimate
        Relative a-posteriori estimate (difference of the last two extrapolants; where the
        film cavitates, difference from the finest unextrapolated force); None if levels = 1.
    r, p
        Nodes (m) and pressure (Pa, gauge) of the finest mesh, shape (G, n_finest + 1).
    dofs
        Unknowns per gap summed over the levels.
    active_set_iterations
        Iterations of the cavitation (obstacle) solve on the finest level (0 without).
    """

    force_viscous: np.ndarray
    force_boundary: np.ndarray
    wetted_radius: np.ndarray
    edge_gap: np.ndarray
    cavitation_radius: np.ndarray
    error_estimate: np.ndarray | None
    r: np.ndarray
    p: np.ndarray
    dofs: int
    active_set_iterations: int

    @property
    def force_total(self) -> np.ndarray:
        """Viscous plus boundary-pressure force (N)."""
        return self.force_viscous + self.force_boundary


def _mapping(profile: GapProfile, xi_w: np.ndarray, s: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """xi(s), dxi/ds and h(s) on the reference coordinate s in [0, 1], shape (G, len(s)).

    sphere-wall and parabolic: ``ln h`` uniform in s (xi(h) is a polynomial);
    sphere-sphere and tabulated: ``ln(1 + xi/xi0)`` uniform, xi0 = 2 R_c S.
    """
    gap = profile.gap[:, None]
    s = s[None, :]
    if profile.shape in ("sphere-wall", "parabolic"):
        edge = profile.h_of_xi(xi_w, profile.gap)[:, None]
        big_l = np.log(edge / gap)
        if np.any(big_l < _FLAT):  # a wetted zone tiny against 2RS: uniform in xi instead
            return _flat_mapping(profile, xi_w, s, big_l[:, 0] < _FLAT)
        e = np.exp(s * big_l)
        rise = gap * np.expm1(s * big_l)                 # h - S without cancellation
        dh_ds = gap * big_l * e
        if profile.shape == "parabolic":
            two_r = 2.0 * profile.radius
            return two_r * rise, two_r * dh_ds, gap + rise
        r = profile.radius
        return rise * (2.0 * r - rise), 2.0 * (r - rise) * dh_ds, gap + rise
    rc = profile.reduced_radius
    xi0 = np.minimum(2.0 * rc * gap, xi_w[:, None]) if math.isfinite(rc) else xi_w[:, None]
    big_l = np.log1p(xi_w[:, None] / xi0)
    xi = xi0 * np.expm1(s * big_l)
    xi_s = xi0 * big_l * np.exp(s * big_l)
    return xi, xi_s, profile.h_of_xi(xi, gap)


#: ln(h_edge/S) below which the ln-h grading degenerates (dh/ds -> 0): the gap is flat over
#: the wetted zone to 1e-9 and a mapping uniform in xi is used for those gaps
_FLAT = 1e-9


def _flat_mapping(profile: GapProfile, xi_w: np.ndarray, s: np.ndarray, flat: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_mapping` with ``xi = xi_w s`` on the gaps marked ``flat`` (a bridge far
    smaller than its gap, e.g. past rupture), the ln-h grading on the others."""
    gap = profile.gap[:, None]
    xi = xi_w[:, None] * s
    out = [xi, np.broadcast_to(xi_w[:, None], xi.shape).copy(), profile.h_of_xi(xi, gap)]
    if not flat.all():
        sub = replace(profile, gap=profile.gap[~flat])
        graded = _mapping(sub, xi_w[~flat], s[0])
        for arr, part in zip(out, graded, strict=True):
            arr[~flat] = part
    return out[0], out[1], out[2]


def _solve_level(profile: GapProfile, xi_w: np.ndarray, n: int, eta: float, v: float,
                 b1: float, b2: float, p_rel_cav: float | None,
                 xi_c_guess: np.ndarray | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """One mesh of n cells: pressures p - p_b at the n + 1 nodes of every gap.

    Rows (vertex-centred FV, xi = r^2, s uniform, ds = 1/n), for node i < n::

        K_{i-1/2} (p_i - p_{i-1}) - K_{i+1/2} (p_{i+1} - p_i) = (v/4) ds (xi_{i+1/2} - xi_{i-1/2})

    with ``K = xi M(h) / (dxi/ds)`` at the faces (K = 0 on the axis: symmetry) and
    p_n = p_b. Returns (viscous force, p - p_b, xi at nodes, xi_c of cavitation, iterations).
    """
    g = profile.gap.size
    ds = 1.0 / n
    s_node = np.linspace(0.0, 1.0, n + 1)
    s_face = (np.arange(n) + 0.5) * ds
    xi_f, xis_f, h_f = _mapping(profile, xi_w, s_face)
    xi_n, xis_n, h_n = _mapping(profile, xi_w, s_node)
    xi_n[:, 0] = 0.0
    xi_n[:, -1] = xi_w
    if np.any(h_n <= 0) or np.any(h_f <= 0) or not np.all(np.isfinite(h_f)):
        bad = np.concatenate([h_n.ravel(), h_f.ravel()])
        raise ValidityError(NAME, f"gap h(r) = {np.nanmin(bad):.6g} m <= 0 inside the wetted "
                            "zone: the surfaces touch or overlap, a dry-contact law (Hertz/JKR) "
                            "applies, not lubrication")
    k = xi_f * slip_mobility(h_f, eta, b1, b2) / xis_f           # (G, n) face coefficients
    # unknowns: nodes 0..n-1 of every gap (p_n = p_b eliminated), stacked gap after gap
    diag = k.copy()
    diag[:, 1:] += k[:, :-1]
    upper = -k[:, :-1]                                           # A[i, i+1], i = 0..n-2
    lower = -k[:, :-1]                                           # A[i+1, i]
    src_faces = np.concatenate([np.zeros((g, 1)), xi_f], axis=1)  # xi at faces -1/2 .. n-1/2
    rhs = 0.25 * v * ds * np.diff(src_faces, axis=1)             # (G, n)
    # K spans many decades along the mesh (~h^4): equilibrate every row to a unit diagonal
    scale = 1.0 / diag
    upper, lower = upper * scale[:, :-1], lower * scale[:, 1:]
    diag, rhs = np.ones_like(diag), rhs * scale
    ab = np.zeros((3, g * n))
    ab[1] = diag.ravel()
    up = np.zeros((g, n))
    up[:, 1:] = upper                                            # ab[0, j] = A[j-1, j]
    lo = np.zeros((g, n))
    lo[:, :-1] = lower                                           # ab[2, j] = A[j+1, j]
    ab[0] = up.ravel()
    ab[2] = lo.ravel()
    b = rhs.ravel()
    iters = 0
    active = np.zeros(g * n, dtype=bool)
    if p_rel_cav is not None and xi_c_guess is not None and np.any(xi_c_guess > 0):
        # warm start from the front of the coarser mesh: a few active-set steps
        guess = (xi_n[:, :n] < xi_c_guess[:, None]).ravel()
        p, active, iters = _obstacle(ab, b, guess, p_rel_cav, n)
    else:
        p = solve_banded((1, 1), ab, b, check_finite=False)
        if p_rel_cav is not None and np.any(p < p_rel_cav):
            p, active, iters = _obstacle(ab, b, p < p_rel_cav, p_rel_cav, n)
    p = p.reshape(g, n)
    p_full = np.concatenate([p, np.zeros((g, 1))], axis=1)
    if not np.all(np.isfinite(p_full)):
        raise SolverError(f"model '{NAME}': non-finite pressure on a mesh of {n} cells")
    integrand = p_full * xis_n
    force = np.pi * ds * (integrand.sum(axis=1) - 0.5 * (integrand[:, 0] + integrand[:, -1]))
    # cavitation front from the exact discrete flux law past the last active node
    act = active.reshape(g, n)
    xi_c = np.zeros(g)
    has = act.any(axis=1)
    if np.any(has):
        last = n - 1 - np.argmax(act[:, ::-1], axis=1)           # last active node per gap
        j = np.minimum(last, n - 2)
        rows = np.arange(g)
        flux = k[rows, j] * (p_full[rows, j + 1] - p_full[rows, j]) / ds
        xi_c = np.where(has, xi_f[rows, j] + 4.0 * flux / v if v != 0 else 0.0, 0.0)
        xi_c = np.clip(xi_c, 0.0, xi_w)
    return force, p_full, xi_n, xi_c, iters


def _obstacle(ab: np.ndarray, b: np.ndarray, active: np.ndarray, p_cav: float, n: int
              ) -> tuple[np.ndarray, np.ndarray, int]:
    """Primal-dual active-set solve of ``A p >= b, p >= p_cav, (A p - b)(p - p_cav) = 0``.

    A is a (scaled) M-matrix, so the iteration converges in finitely many steps
    (Hintermueller, Ito & Kunisch 2003, SIAM J. Optim. 13, 865).
    """
    def matvec(x: np.ndarray) -> np.ndarray:
        y = ab[1] * x
        y[:-1] += ab[0, 1:] * x[1:]
        y[1:] += ab[2, :-1] * x[:-1]
        return y

    for it in range(1, MAX_ACTIVE_SET_ITER + 1):
        m = ab.copy()
        rhs = b.copy()
        idx = np.flatnonzero(active)
        m[1, idx] = 1.0
        m[0, idx[idx + 1 < m.shape[1]] + 1] = 0.0               # A[i, i+1] of active rows
        m[2, idx[idx > 0] - 1] = 0.0                             # A[i, i-1] of active rows
        rhs[idx] = p_cav
        p = solve_banded((1, 1), m, rhs, check_finite=False)
        lam = matvec(p) - b
        tol = 1e-12 * (abs(p_cav) + float(np.max(np.abs(p))))
        new = np.where(active, lam > tol, p < p_cav - 1e-14 * abs(p_cav))
        if np.array_equal(new, active):
            return p, active, it
        active = new
    raise SolverError(f"model '{NAME}': cavitation active set did not settle in "
                      f"{MAX_ACTIVE_SET_ITER} iterations on a mesh of {n} cells")


def solve_reynolds(profile: GapProfile, *, viscosity: float, velocity: float,
                   wetted_radius: Any = None, edge_gap: Any = None, volume: Any = None,
                   slip_lengths: tuple[float, float] = (0.0, 0.0),
                   boundary_pressure: float = 0.0,
                   cavitation_pressure: float | None = P_CAV_DEFAULT,
                   n: int = 48, levels: int = 3) -> ReynoldsSolution:
    """Solve the axisymmetric Reynolds equation in a wetted disk; force on the sphere.

    ``(1/r) d/dr (r M(h) dp/dr) = -v`` on 0 <= r <= r_w, ``p'(0) = 0``, ``p(r_w) = p_b``,
    ``p >= p_cav`` (see the module docstring). The wetted radius comes from exactly one of
    ``wetted_radius`` (r_w), ``edge_gap`` (a film of thickness H: h(r_w) = H) or ``volume``
    (the liquid between the surfaces: ``int_0^{r_w} 2 pi r h dr = V``).

    Parameters
    ----------
    profile
        The gap, e.g. ``GapProfile.sphere_wall(S, R)``; S may be an array (one solve).
    viscosity
        eta (Pa s), > 0.
    velocity
        v = -dS/dt (m/s), positive = approach.
    wetted_radius, edge_gap, volume
        r_w (m), H (m) or V (m^3); scalars or arrays matching the gaps.
    slip_lengths
        Navier slip lengths (b1, b2) (m) of the two surfaces, >= 0.
    boundary_pressure
        p_b - p_ambient at r = r_w (Pa): 0 for ambient, the Laplace pressure for a meniscus.
    cavitation_pressure
        p_cav - p_ambient (Pa), the floor of the pressure; ``None`` for no cavitation.
    n, levels
        Cells of the coarsest mesh and number of meshes (n, 2n, 4n, ...) extrapolated:
        the force converges at order 2 * levels (cavitation: about 2, the front is not
        aligned with the mesh).

    Returns
    -------
    ReynoldsSolution
    """
    eta = _pos("viscosity", viscosity)
    v = float(velocity)
    if not math.isfinite(v):
        raise InputError(f"velocity = {velocity!r}; allowed: a finite number (m/s)")
    b1, b2 = (float(x) for x in slip_lengths)
    if not (b1 >= 0 and b2 >= 0 and math.isfinite(b1) and math.isfinite(b2)):
        raise InputError(f"slip_lengths = {slip_lengths!r}; allowed: finite numbers >= 0 m")
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 2 <= n <= 1_000_000:
        raise InputError(f"n = {n!r}; allowed: an integer in [2, 1000000]")
    if isinstance(levels, bool) or not isinstance(levels, int | np.integer) or not 1 <= levels <= 5:
        raise InputError(f"levels = {levels!r}; allowed: an integer in [1, 5]")
    p_b = float(boundary_pressure)
    if not math.isfinite(p_b):
        raise InputError(f"boundary_pressure = {boundary_pressure!r}; allowed: finite (Pa)")
    p_rel_cav = None
    if cavitation_pressure is not None:
        p_cav = float(cavitation_pressure)
        if not (math.isfinite(p_cav) and p_cav <= p_b):
            raise InputError(f"cavitation_pressure = {cavitation_pressure!r} Pa; allowed: a "
                             f"finite number <= boundary_pressure = {p_b:g} Pa, or None")
        p_rel_cav = p_cav - p_b

    xi_w = wetted_xi(profile, wetted_radius=wetted_radius, edge_gap=edge_gap, volume=volume)
    forces, xi_c, iters = [], np.zeros(profile.gap.size), 0
    p_fine = xi_fine = None
    for lev in range(levels):
        f, p_fine, xi_fine, xi_c, iters = _solve_level(
            profile, xi_w, n * 2**lev, eta, v, b1, b2, p_rel_cav, xi_c if lev else None)
        forces.append(f)
    table = [forces]                                          # Richardson tableau
    for j in range(1, levels):
        prev = table[-1]
        fac = 4.0**j
        table.append([(fac * prev[i + 1] - prev[i]) / (fac - 1.0) for i in range(len(prev) - 1)])
    best = table[-1][0]
    if levels >= 2:
        second = table[-2][-1]
        scale = np.maximum(np.abs(best), np.finfo(float).tiny)
        err = np.where(best != 0, np.abs(best - second) / scale, 0.0)
        # a cavitation front cuts cells: the error expansion is not smooth there, so judge
        # the extrapolation by its distance from the finest plain solution instead
        cav = xi_c > 0
        err = np.where(cav, np.abs(best - forces[-1]) / scale, err)
    else:
        err = None                                            # one mesh: no estimate
    assert p_fine is not None and xi_fine is not None
    r_w = np.sqrt(xi_w)
    return ReynoldsSolution(
        force_viscous=best, force_boundary=np.pi * xi_w * p_b, wetted_radius=r_w,
        edge_gap=profile.h_of_xi(xi_w, profile.gap), cavitation_radius=np.sqrt(xi_c),
        error_estimate=err, r=np.sqrt(xi_fine), p=p_fine + p_b,
        dofs=int(sum(n * 2**lev for lev in range(levels))), active_set_iterations=iters)


def wetted_xi(profile: GapProfile, *, wetted_radius: Any = None, edge_gap: Any = None,
              volume: Any = None) -> np.ndarray:
    """xi_w = r_w^2 (m^2) per gap from exactly one liquid specification, validated.

    Raises :class:`ValidityError` (use ``stokes``) beyond a sphere's equator or where the
    sphere's surface at the edge is steeper than 60 degrees (r_w^2 > 0.75 R_min^2).
    """
    given = [k for k, x in (("wetted_radius", wetted_radius), ("edge_gap", edge_gap),
                            ("volume", volume)) if x is not None]
    if len(given) != 1:
        raise InputError(f"liquid amount: got {given or 'none'}; allowed: exactly one of "
                         "wetted_radius, edge_gap (film thickness), volume")
    g = profile.gap
    eq = profile.equator_xi
    if wetted_radius is not None:
        rw = np.broadcast_to(np.asarray(wetted_radius, dtype=float), g.shape)
        if not np.all(np.isfinite(rw)) or np.any(rw <= 0):
            raise InputError(f"wetted_radius = {wetted_radius!r}; allowed: finite > 0 m")
        xi_w = rw * rw
        if np.any(xi_w >= eq):
            raise ValidityError(NAME, f"wetted radius {np.sqrt(xi_w.max()):.6g} m is at or "
                                f"beyond the equator r = {math.sqrt(eq):.6g} m", "stokes")
    elif edge_gap is not None:
        hh = np.broadcast_to(np.asarray(edge_gap, dtype=float), g.shape)
        if not np.all(np.isfinite(hh)) or np.any(hh <= g):
            raise InputError(f"edge_gap (film thickness) = {edge_gap!r}; allowed: finite and "
                             "> the gap S at every gap (else the sphere does not touch it)")
        if profile.shape == "sphere-wall" and np.any(hh - g >= profile.radius):
            i = int(np.argmax(hh - g >= profile.radius))
            raise ValidityError(NAME, f"film thickness {hh[i]:.6g} m at gap {g[i]:.6g} m wets "
                                f"the sphere beyond its equator (delta - S >= R = "
                                f"{profile.radius:.6g} m)", "stokes")
        xi_w = profile.xi_of_edge_gap(hh)
    else:
        vol = np.broadcast_to(np.asarray(volume, dtype=float), g.shape)
        if not np.all(np.isfinite(vol)) or np.any(vol <= 0):
            raise InputError(f"volume = {volume!r}; allowed: finite > 0 m^3")
        if math.isfinite(eq):
            vmax = profile.volume_between(np.full(g.shape, eq))
            if np.any(vol >= vmax):
                i = int(np.argmax(vol >= vmax))
                raise ValidityError(NAME, f"bridge volume {vol[i]:.6g} m^3 at gap {g[i]:.6g} m "
                                    f"reaches beyond the sphere's equator (max {vmax[i]:.6g} "
                                    "m^3 for lubrication)", "stokes")
        xi_w = profile.xi_of_volume(vol)
    if profile.shape in ("sphere-wall", "sphere-sphere") and np.any(xi_w > MAX_XI_FRACTION * eq):
        i = int(np.argmax(xi_w > MAX_XI_FRACTION * eq))
        what = "bridge volume" if volume is not None else "liquid amount"
        raise ValidityError(NAME, f"{what} too large for the lubrication approximation: wetted "
                            f"radius {math.sqrt(xi_w[i]):.6g} m at gap {g[i]:.6g} m where the "
                            f"sphere is steeper than 60 deg (allowed r_w <= "
                            f"{math.sqrt(MAX_XI_FRACTION * eq):.6g} m)", "stokes")
    if profile.shape == "tabulated" and np.any(xi_w > profile.xi_max * (1 + 1e-12)):
        raise InputError(f"wetted radius {np.sqrt(xi_w.max()):.6g} m beyond the tabulated gap "
                         f"(r <= {math.sqrt(profile.xi_max):.6g} m)")
    return xi_w


# ---- the registered model ----------------------------------------------------------------


@register
class Lubrication(Model):
    """Axisymmetric Reynolds equation with finite liquid, slip and cavitation (level 1).

    Options (``model.force(scene, **opts)``): ``gap_shape`` = ``"sphere"`` (exact caps,
    default) or ``"parabolic"``; ``wetted_radius`` (m) instead of the scene's liquid amount;
    ``boundary_pressure`` (Pa, gauge, default 0 = ambient); ``cavitation_pressure`` (Pa,
    gauge, default -101325 = absolute zero; ``None`` disables); ``n``, ``levels``.
    A bridge's wetted radius assumes its whole volume V lies between the surfaces:
    ``int_0^{r_w} 2 pi r h dr = V`` (no liquid outside the edge, meniscus volume ignored).
    """

    name: ClassVar[str] = NAME
    level: ClassVar[int] = 1
    component: ClassVar[str] = "viscous"
    order: ClassVar[float | None] = 6.0
    reference_rank: ClassVar[dict[str, int]] = {"viscous": 10}
    reference: ClassVar[str] = ("Reynolds equation, axisymmetric squeeze film; finite liquid "
                                "Pitois et al. 2000; Navier slip Vinogradova 1995")
    source: ClassVar[str] = ("axisymmetric Reynolds equation (Reynolds 1886), finite volumes "
                             "with Richardson extrapolation; checked against Pitois, Moucheront "
                             "& Chateau 2000 (finite liquid) and Vinogradova 1995 (Navier slip)")
    validity: ClassVar[str] = ("thin wetted gap (film or bridge) with r_w <= (sqrt 3/2) R_min "
                               "(surface slope <= 60 deg); a bridge short of its rupture "
                               "distance; not immersed (use 'stokes'); "
                               "quasi-steady, no inertia, rigid surfaces unless a gap is given")
    presets: ClassVar[dict[str, dict[str, Any]]] = {
        "fast": {"n": 24, "levels": 2},
        "default": {"n": 48, "levels": 3},
        "accurate": {"n": 128, "levels": 3},
    }

    def check(self, scene: Scene) -> None:
        """Refuse immersed scenes and liquid amounts beyond the thin-gap validity."""
        if scene.amount == "immersed":
            raise ValidityError(NAME, "an immersed sphere is outside the thin-gap (finite "
                                "liquid) lubrication model", "stokes")
        wet, _ = self._touching(scene)
        wetted_xi(self._profile(wet, "sphere"), **self._amount(wet))

    @staticmethod
    def _touching(scene: Scene) -> tuple[Scene, np.ndarray]:
        """The scene restricted to the gaps where the sphere touches the liquid, and the mask.

        A film of thickness delta is touched only where S < delta; at S >= delta the sphere
        is above the film and the liquid force is exactly zero.
        """
        gaps = scene.gap_array
        if scene.amount != "film":
            return scene, np.ones(gaps.shape, bool)
        mask = gaps < scene.film_thickness
        if not mask.any():
            raise ValidityError(NAME, f"every gap is >= the film thickness "
                                f"{scene.film_thickness:g} m: the sphere never touches the film")
        return scene.with_gaps(gaps[mask].tolist()), mask

    @staticmethod
    def _profile(scene: Scene, gap_shape: str) -> GapProfile:
        if gap_shape == "parabolic":
            return GapProfile.parabolic(scene.gap_array, scene.reduced_radius)
        if gap_shape != "sphere":
            raise InputError(f"gap_shape = {gap_shape!r}; allowed: 'sphere', 'parabolic'")
        if scene.kind == "sphere-wall":
            return GapProfile.sphere_wall(scene.gap_array, scene.radius)
        assert scene.radius2 is not None
        return GapProfile.sphere_sphere(scene.gap_array, scene.radius, scene.radius2)

    @staticmethod
    def _amount(scene: Scene, wetted_radius: Any = None) -> dict[str, Any]:
        if wetted_radius is not None:
            return {"wetted_radius": wetted_radius}
        if scene.amount == "film":
            return {"edge_gap": scene.film_thickness}
        return {"volume": scene.bridge_volume}

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        known = {"n", "levels", "gap_shape", "wetted_radius", "boundary_pressure",
                 "cavitation_pressure"}
        unknown = set(opts) - known
        if unknown:
            raise InputError(f"model '{NAME}': unknown option(s) {sorted(unknown)}; allowed: "
                             + ", ".join(sorted(known)))
        full, (scene, mask) = scene, self._touching(scene)
        profile = self._profile(scene, opts.get("gap_shape", "sphere"))
        p_b = float(opts.get("boundary_pressure", 0.0))
        sol = solve_reynolds(
            profile, viscosity=scene.viscosity, velocity=scene.velocity,
            slip_lengths=(scene.slip_length_sphere, scene.slip_length_wall),
            boundary_pressure=p_b,
            cavitation_pressure=opts.get("cavitation_pressure", P_CAV_DEFAULT),
            n=opts.get("n", 48), levels=opts.get("levels", 3),
            **self._amount(scene, opts.get("wetted_radius")))
        def on_all_gaps(values: np.ndarray, dry: float = 0.0) -> np.ndarray:
            """Values at the touching gaps, ``dry`` where the sphere is above the film."""
            out = np.full(mask.shape, dry)
            out[mask] = values
            return out

        return ForceCurve(
            case=scene.name, model=NAME, gap=full.gap_array,
            force_viscous=on_all_gaps(sol.force_viscous),
            force_capillary=on_all_gaps(sol.force_boundary) if p_b != 0.0 else None,
            extras={"wetted_radius": on_all_gaps(sol.wetted_radius),
                    "edge_gap": on_all_gaps(sol.edge_gap, full.film_thickness or 0.0),
                    "cavitation_radius": on_all_gaps(sol.cavitation_radius),
                    "boundary_pressure_force": on_all_gaps(sol.force_boundary),
                    "axis_pressure": on_all_gaps(sol.p[:, 0])},
            error_estimate=on_all_gaps(sol.error_estimate),
            diagnostics={"dofs_per_gap": sol.dofs, "levels": opts.get("levels", 3),
                         "active_set_iterations": sol.active_set_iterations,
                         **({"outside_stated_validity": note}
                            if (note := past_rupture_note(full)) else {})},
        )

    def convergence_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Mesh sizes 1/n and relative errors of the default scheme (levels = 3).

        Case: exact sphere-wall gap, S/R = 1e-3, film delta/R = 0.05, no slip; reference
        the adaptive quadrature ``6 pi eta v int_0^{r_w} r^3/h^3 dr`` (scipy.integrate.quad).
        """
        radius, gap, film = 1.0, 1e-3, 0.05
        prof = GapProfile.sphere_wall(gap, radius)
        ref = quadrature_force(prof.h, math.sqrt(prof.xi_of_edge_gap(np.array([film]))[0]),
                               1.0, 1.0, scale=math.sqrt(2 * radius * gap))
        ns = np.array([4, 6, 8, 12, 16])
        errs = [abs(solve_reynolds(prof, viscosity=1.0, velocity=1.0, edge_gap=film, n=int(k),
                                   levels=3).force_viscous[0] / ref - 1.0) for k in ns]
        return 1.0 / ns, np.array(errs)


def quadrature_force(h: Callable[[np.ndarray], np.ndarray], r_w: float, eta: float, v: float,
                     scale: float, b1: float = 0.0, b2: float = 0.0) -> float:
    """Independent check: ``F = (pi v / 2) int_0^{r_w} r^3 / M(h(r)) dr`` by adaptive quadrature.

    For rigid no-slip surfaces this is ``6 pi eta v int_0^{r_w} r^3/h^3 dr``. The integral
    is split at multiples of ``scale`` (about sqrt(R S)) so that QUADPACK sees the peak.
    """
    from scipy.integrate import quad

    def f(r: float) -> float:
        hr = float(h(np.array(r)))
        return r**3 / float(slip_mobility(np.array(hr), eta, b1, b2))

    edges = [0.0]
    x = scale
    while x < r_w:
        edges.append(x)
        x *= 2.0
    edges.append(r_w)
    total = sum(quad(f, a, b, epsabs=0.0, epsrel=1e-13, limit=200)[0]
                for a, b in zip(edges[:-1], edges[1:], strict=True))
    return 0.5 * math.pi * v * total
