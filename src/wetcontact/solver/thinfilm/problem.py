r"""The film problem: grid, gap, pressure (Laplace, hydrostatic, penalty contact, wetting)
and mobility of the thin-film equation, in conservative finite-volume form.

.. math::
    \partial_t h + \frac{1}{r}\partial_r (r q) = 0, \qquad q = -M(h)\, \partial_r p,

:math:`M = h^3/(3\eta)` where the surface is free, :math:`M = g^3/(12\eta)` where the liquid
fills the gap, :math:`p = -\sigma \nabla^2 h + \rho g_{\rm acc} h + k\max(0, h - g) + p_w`
(see the package docstring). Sources: Oron, Davis & Bankoff (1997) Rev. Mod. Phys. 69, 931;
Kikuchi & Oden (1988) "Contact problems in elasticity" (penalty method).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pde
import scipy.sparse as sp

from wetcontact.errors import InputError

# ---- the grid -----------------------------------------------------------------------


def graded_faces(cells: int, domain: float, fine_radius: float, growth: float) -> np.ndarray:
    r"""Faces of a graded grid: uniform on [0, r_f], geometric beyond, ending at L.

    ``n_f`` uniform cells of width :math:`r_f/n_f` then :math:`n_c = N - n_f` cells of
    widths :math:`c\,d\,q^k` (k = 1 .. n_c, q = ``growth``), :math:`c \le 1` scaling them
    to end exactly at L; n_f is the largest count for which :math:`c \le 1` (the coarse
    cells never outgrow the geometric law). The face-centred finite volumes stay
    conservative on any grid; on this smoothly graded one the flux error stays second
    order (the cell-width jump is at most q).

    Raises
    ------
    InputError
        If the counts cannot reach L with q (too few cells) or r_f is outside (0, L).
    """
    if not 0.0 < fine_radius < domain:
        raise InputError(f"thinfilm: fine_radius = {fine_radius!r}; allowed: (0, domain = "
                         f"{domain:g}) m")
    if not 1.0 < growth <= 1.5:
        raise InputError(f"thinfilm: growth = {growth!r}; allowed: (1, 1.5]")

    def coarse_sum(n_f: int) -> float:
        d, n_c = fine_radius / n_f, cells - n_f
        return d * growth * (growth**n_c - 1.0) / (growth - 1.0)

    n_f = cells - 1
    while n_f >= 1 and coarse_sum(n_f) < domain - fine_radius:
        n_f -= 1
    if n_f < 1:
        raise InputError(f"thinfilm: cells = {cells} cannot reach the domain with growth "
                         f"{growth:g}; allowed: more cells")
    d = fine_radius / n_f
    widths = d * growth ** np.arange(1, cells - n_f + 1)
    widths *= (domain - fine_radius) / widths.sum()
    faces = np.concatenate((np.arange(n_f + 1) * d, fine_radius + np.cumsum(widths)))
    faces[-1] = domain
    return faces


def graded_cells(dr_fine: float, domain: float, fine_radius: float, growth: float) -> int:
    """Cells of a :func:`graded_faces` grid whose fine cells are at most ``dr_fine`` wide."""
    n_f = math.ceil(fine_radius / dr_fine)
    d = fine_radius / n_f
    n_c = math.ceil(math.log(1.0 + (domain - fine_radius) * (growth - 1.0) / (d * growth))
                    / math.log(growth))
    return n_f + n_c


# ---- the problem --------------------------------------------------------------------


@dataclass(frozen=True)
class FilmPhysics:
    """The physical parameters of a sphere approaching a film (SI units), shared by the
    penalty-contact :class:`FilmProblem` and the sharp-contact
    :class:`~wetcontact.solver.thinfilm.sharp.SharpFilm`.

    Attributes
    ----------
    radius, viscosity, surface_tension, density, gravity, film_thickness, velocity
        R (m), eta (Pa s), sigma (N/m), rho (kg/m^3), g (m/s^2), delta (m), v (m/s).
    """

    radius: float
    viscosity: float
    surface_tension: float
    density: float
    gravity: float
    film_thickness: float
    velocity: float


@dataclass(frozen=True)
class FilmProblem(FilmPhysics):
    r"""Parameters and grid of one thin-film run (SI units).

    Attributes
    ----------
    radius, viscosity, surface_tension, density, gravity, film_thickness, velocity
        From :class:`FilmPhysics`.
    cells
        Number of finite-volume cells on [0, L].
    domain
        Outer radius L (m).
    fine_radius
        ``None``: uniform cells. Else the graded grid of :func:`graded_faces`: uniform
        fine cells on [0, fine_radius] (the contact zone and the path of the contact
        line), then cells growing by the factor ``growth`` out to L.
    growth
        Ratio of neighbouring cell widths outside ``fine_radius``.
    penetration
        Penalty parameter epsilon (relative penetration of the liquid into the sphere).
    gap_shape
        ``"parabolic"`` (S + r^2/2R), ``"sphere"`` (exact) or ``"none"`` (no sphere).
    contact
        ``"tangential"``: the free surface meets the sphere tangentially (a non-wetting,
        180 deg contact); ``"meniscus"``: a wetting meniscus at the wetted edge with the
        spreading energy :math:`W = \sigma(\cos\theta_s + \cos\theta_w)` (see
        :meth:`wetting_pressure`).
    angle_sphere, angle_wall
        Contact angles (rad) of the meniscus on the sphere and on its lower side: the
        film's own surface (0, default) or the wall.
    wetting_width
        lambda: relative width (in h/g) of the diffuse contact zone of the meniscus model.
    """

    cells: int
    domain: float
    penetration: float = 1e-3
    gap_shape: str = "parabolic"
    contact: str = "tangential"
    angle_sphere: float = math.pi
    angle_wall: float = 0.0
    wetting_width: float = 0.05
    fine_radius: float | None = None
    growth: float = 1.03
    grid: pde.PolarSymGrid = field(init=False, repr=False, compare=False)
    r_c: np.ndarray = field(init=False, repr=False, compare=False)
    r_f: np.ndarray = field(init=False, repr=False, compare=False)
    vol: np.ndarray = field(init=False, repr=False, compare=False)
    area: np.ndarray = field(init=False, repr=False, compare=False)
    dc: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.gap_shape not in ("parabolic", "sphere", "none"):
            raise InputError(f"thinfilm: gap_shape = {self.gap_shape!r}; allowed: "
                             "'parabolic', 'sphere', 'none'")
        if not (isinstance(self.cells, int | np.integer) and self.cells >= 8):
            raise InputError(f"thinfilm: cells = {self.cells!r}; allowed: an integer >= 8")
        if self.contact not in ("tangential", "meniscus"):
            raise InputError(f"thinfilm: contact = {self.contact!r}; allowed: "
                             "'tangential', 'meniscus'")
        if not 0.0 < self.wetting_width <= 0.5:
            raise InputError(f"thinfilm: wetting_width = {self.wetting_width!r}; allowed: "
                             "(0, 0.5]")
        for name in ("angle_sphere", "angle_wall"):
            if not 0.0 <= getattr(self, name) <= math.pi:
                raise InputError(f"thinfilm: {name} = {getattr(self, name)!r}; allowed: "
                                 "[0, pi] rad")
        if not self.penetration > 0:
            raise InputError(f"thinfilm: penetration = {self.penetration!r}; allowed: > 0")
        if self.fine_radius is None:
            r_f = np.arange(self.cells + 1) * (self.domain / self.cells)
        else:
            r_f = graded_faces(int(self.cells), self.domain, self.fine_radius, self.growth)
        # py-pde's grid only holds the cell values for its solvers (the geometry is ours)
        object.__setattr__(self, "grid", pde.PolarSymGrid((0.0, self.domain), int(self.cells)))
        object.__setattr__(self, "r_f", r_f)
        object.__setattr__(self, "r_c", 0.5 * (r_f[1:] + r_f[:-1]))
        object.__setattr__(self, "dc", np.diff(0.5 * (r_f[1:] + r_f[:-1])))
        object.__setattr__(self, "vol", np.pi * (r_f[1:] ** 2 - r_f[:-1] ** 2))
        object.__setattr__(self, "area", 2.0 * np.pi * r_f)

    @property
    def dr(self) -> float:
        """Width of the first (smallest) cell (m); the cell width of a uniform grid."""
        return float(self.r_f[1])

    def gap(self, r: np.ndarray, s: float) -> np.ndarray:
        """Gap g(r) between wall and sphere at surface gap S (m); +inf without a sphere."""
        if self.gap_shape == "parabolic":
            return s + r**2 / (2.0 * self.radius)
        if self.gap_shape == "sphere":
            rr = np.minimum(r, self.radius)
            out = s + self.radius - np.sqrt(self.radius**2 - rr**2)
            return np.where(r < self.radius, out, np.inf)
        return np.full_like(r, np.inf)

    def surface_gap(self, t: float) -> float:
        """S(t) = delta - v t (prescribed constant speed from first touch)."""
        return self.film_thickness - self.velocity * t

    def penalty_stiffness(self, s: float) -> float:
        """k = P_ref(S)/(epsilon S), P_ref = 3 eta v R/S^2 + sigma/R + rho g delta."""
        p_ref = (3.0 * self.viscosity * abs(self.velocity) * self.radius / s**2
                 + self.surface_tension / self.radius
                 + self.density * self.gravity * self.film_thickness)
        return p_ref / (self.penetration * s)

    # ---- the operator --------------------------------------------------------------

    def laplacian(self, h: np.ndarray) -> np.ndarray:
        """Conservative FV Laplacian (1/r)(r h')' with h' = 0 at r = 0 and r = L."""
        flux = np.zeros(self.cells + 1)
        flux[1:-1] = self.area[1:-1] * np.diff(h) / self.dc
        return np.diff(flux) / self.vol

    @property
    def spreading_energy(self) -> float:
        """W = sigma (cos theta_s + cos theta_w) (N/m) for ``contact = "meniscus"``, else 0."""
        if self.contact != "meniscus":
            return 0.0
        return self.surface_tension * (math.cos(self.angle_sphere)
                                       + math.cos(self.angle_wall))

    def wetted_fraction(self, h: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """f(x) and df/dx, x = h/g: C1 smoothstep from 0 at x = 1 - lambda to 1 at x = 1."""
        lam = self.wetting_width
        y = np.clip((h / g - 1.0 + lam) / lam, 0.0, 1.0)
        return y * y * (3.0 - 2.0 * y), 6.0 * y * (1.0 - y) / lam

    def wetting_pressure(self, h: np.ndarray, s: float) -> np.ndarray:
        r"""Pressure of the meniscus wetting energy, :math:`p_w = -W f'(h/g)/g`.

        The free energy gains :math:`-W` per unit area of sphere wetted by the liquid,
        :math:`E_w = -\int W f(h/g)\,dA`, f the wetted fraction (a step regularised over
        :math:`1-\lambda \le h/g \le 1`). Filling the gap at the wetted edge over an area
        dA takes the volume :math:`(g - h_o)\,dA` (h_o the film at the meniscus foot), so
        the static edge pressure is :math:`dE_w/dV = -W/(g - h_o)`: the Laplace pressure
        of the two-plate meniscus spanning the local gap,
        :math:`-\sigma(\cos\theta_s + \cos\theta_w)/d` (Fisher 1926; e.g. Israelachvili,
        "Intermolecular and Surface Forces", 3rd ed., sec. 17.7), independent of lambda.
        """
        w = self.spreading_energy
        if w == 0.0 or self.gap_shape == "none":
            return np.zeros_like(h)
        g = self.gap(self.r_c, s)
        _, df = self.wetted_fraction(h, g)
        return -w * df / g

    def pressure(self, h: np.ndarray, s: float) -> np.ndarray:
        """p = -sigma lap(h) + rho g h + k max(0, h - g) + p_w at the cell centres (Pa)."""
        p = -self.surface_tension * self.laplacian(h) + self.density * self.gravity * h
        if self.gap_shape != "none":
            g = self.gap(self.r_c, s)
            p = p + self.penalty_stiffness(s) * np.maximum(h - g, 0.0)
            if self.contact == "meniscus":
                p = p + self.wetting_pressure(h, s)
        return p

    def face_mobility(self, h: np.ndarray, s: float) -> np.ndarray:
        """Mobility on the interior faces: h^3/(3 eta) free, min(h, g)^3/(12 eta) confined."""
        hf = 0.5 * (h[1:] + h[:-1])
        if self.gap_shape == "none":
            return hf**3 / (3.0 * self.viscosity)
        gf = self.gap(self.r_f[1:-1], s)
        # smooth switch (C1 smoothstep) over h_f - g_f in [-eps g_f, 0], the penalty's
        # own resolution, so the integrator sees no jump when the contact line crosses a
        # face; the ramp vanishes with eps
        x = np.clip((hf - gf) / (self.penetration * gf) + 1.0, 0.0, 1.0)
        confined = x * x * (3.0 - 2.0 * x)
        return np.minimum(hf, gf) ** 3 / (3.0 * self.viscosity) * (1.0 - 0.75 * confined)

    def rate(self, h: np.ndarray, t: float) -> np.ndarray:
        """dh/dt at time t of the prescribed-speed run, S = delta - v t."""
        return self.rate_gap(h, self.surface_gap(t))

    def rate_gap(self, h: np.ndarray, s: float) -> np.ndarray:
        """dh/dt = -(1/V_i)(A_{i+1/2} q_{i+1/2} - A_{i-1/2} q_{i-1/2}) at surface gap S,
        zero end fluxes."""
        p = self.pressure(h, s)
        flux = np.zeros(self.cells + 1)
        flux[1:-1] = -self.area[1:-1] * self.face_mobility(h, s) * np.diff(p) / self.dc
        return -np.diff(flux) / self.vol

    def jac_sparsity(self) -> sp.csr_matrix:
        """Pentadiagonal pattern: dh_i/dt depends on h_{i-2..i+2}."""
        n = self.cells
        return sp.diags([np.ones(n - abs(k)) for k in range(-2, 3)], range(-2, 3),
                        format="csr")

    def volume(self, h: np.ndarray) -> float:
        """Liquid volume 2 pi int h r dr (m^3), exact for the cell averages."""
        return float(np.dot(self.vol, h))

