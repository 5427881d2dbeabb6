"""gmsh builders for the meridian half-plane (r >= 0) of the axisymmetric contact geometries.

One function per geometry. Every builder works in units of the sphere radius (R = 1), so a
mesh depends only on dimensionless numbers (S/R, delta/R, the resolution) and is shared by
all scenes with the same ratios; the solver scales the result (Stokes flow is linear).
Coordinates: ``x`` is the radial coordinate r, ``y`` the axial coordinate z.

Every boundary carries a named gmsh physical group, read back through meshio and handed to
scikit-fem as ``mesh.boundaries[name]``:

``axis``          r = 0 (symmetry axis)
``wall``          the no-slip plane z = 0
``symmetry``      a shear-free symmetry plane z = 0 (two equal spheres, half domain)
``sphere``        the (upper) sphere, the one whose force is reported
``sphere2``       the lower sphere of the full two-sphere mesh
``far``           the truncated far boundary
``free_surface``  a liquid-gas interface (film surface, bridge meniscus)

Element sizes come from a size callback (:func:`_sphere_size`): in the gap between the
sphere and the plane (r < R, below the sphere's centre) the size is ``h(r)/n_gap`` with
``h(r) = S + R - sqrt(R^2 - r^2)`` the local gap, so the number of elements across the gap is
the same at every S/R; elsewhere the size is ``h_sphere + growth * d`` (d the distance to the
sphere), which reaches the far boundary at L/R = ``far`` with a few hundred elements. The mesh
is second order (6-node triangles) with the mid-edge nodes placed on the exact circle of the
sphere (isoparametric P2 geometry), which a 1e-5 force needs.
"""

from __future__ import annotations

import math
import os
import tempfile
from bisect import bisect_right
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import meshio
import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.meshes.io import read_msh

SizeFn = Callable[[float, float], float]

ZTOL = 1e-12
"""Tolerance (units of R) on the axial bounds of a gap column in the size fields."""

MIN_CORNER = 1.0e-7
"""Smallest element size (units of R) at the film's corner: below 1e-7 R the isoparametric
inversion of scikit-fem loses convergence (the same floor as the bridges' smallest slip
length, ``wetcontact.solver.stokes.model.MIN_BRIDGE_SLIP``)."""


@dataclass(frozen=True)
class Resolution:
    """Mesh resolution, in units of the sphere radius R.

    Attributes
    ----------
    n_gap
        Elements across the gap between the sphere and the plane, along the whole gap
        (the size there is ``h(r)/n_gap``).
    h_sphere
        Element size on the sphere away from the gap (units of R).
    growth
        Size growth with the distance d from the sphere: size = h_sphere + growth * d.
    far
        Radius L/R of the far boundary (a circle about the contact point or the sphere).
    n_film
        Elements across a liquid film (film geometry only).
    film_corner
        Element size at the corner where the sphere meets the flat film surface, over the
        film thickness delta (film geometry only; floored at :data:`MIN_CORNER` R). The
        flow has a stick-slip singularity there (velocity ~ rho^(1/2) in the distance rho
        from the corner), so the force error is first order in this size: see
        :func:`sphere_film`.
    """

    n_gap: int = 4
    h_sphere: float = 0.05
    growth: float = 0.3
    far: float = 1.0e4
    n_film: int = 6
    film_corner: float = 5.0e-4

    def __post_init__(self) -> None:
        if not (isinstance(self.n_gap, int) and 1 <= self.n_gap <= 200):
            raise InputError(f"Resolution.n_gap = {self.n_gap!r}; allowed: integer in [1, 200]")
        if not 1e-4 <= self.h_sphere <= 1.0:
            raise InputError(f"Resolution.h_sphere = {self.h_sphere!r}; allowed: [1e-4, 1] R")
        if not 0.02 <= self.growth <= 2.0:
            raise InputError(f"Resolution.growth = {self.growth!r}; allowed: [0.02, 2]")
        if not 5.0 <= self.far <= 1e8:
            raise InputError(f"Resolution.far = {self.far!r}; allowed: [5, 1e8] R")
        if not (isinstance(self.n_film, int) and 1 <= self.n_film <= 200):
            raise InputError(f"Resolution.n_film = {self.n_film!r}; allowed: integer in [1, 200]")
        if not 1e-6 <= self.film_corner <= 0.5:
            raise InputError(f"Resolution.film_corner = {self.film_corner!r}; allowed: "
                             "[1e-6, 0.5] (corner element size over the film thickness)")

    def scaled(self, factor: float) -> Resolution:
        """Uniformly refined copy: every element size divided by ``factor``."""
        return Resolution(n_gap=max(1, round(self.n_gap * factor)),
                          h_sphere=self.h_sphere / factor, growth=self.growth / factor,
                          far=self.far, n_film=max(1, round(self.n_film * factor)),
                          film_corner=self.film_corner / factor)


# ---- gmsh session ---------------------------------------------------------------------


class _Gmsh:
    """Context manager: an initialised, silent gmsh with one empty model."""

    def __init__(self, name: str):
        self.name = name

    def __enter__(self):
        import gmsh

        if gmsh.isInitialized():
            gmsh.finalize()
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay: good quality
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.model.add(self.name)
        return gmsh

    def __exit__(self, *exc):
        import gmsh

        gmsh.finalize()
        return False


def _mesh_and_read(gmsh, size: SizeFn, groups: dict[str, list[int]], surface: int) -> meshio.Mesh:
    """Name the groups, mesh with ``size``, elevate to order 2 and read back with meshio."""
    gmsh.model.geo.synchronize()
    for name, curves in groups.items():
        if curves:
            gmsh.model.addPhysicalGroup(1, curves, name=name)
    gmsh.model.addPhysicalGroup(2, [surface], name="fluid")
    gmsh.model.mesh.setSizeCallback(lambda dim, tag, x, y, z, lc: float(size(x, y)))
    try:
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
    except Exception as exc:  # gmsh raises a plain Exception
        raise SolverError(f"gmsh failed to mesh '{gmsh.model.getCurrent()}': {exc}") from exc
    fd, tmp = tempfile.mkstemp(suffix=".msh")
    os.close(fd)
    try:
        gmsh.write(tmp)
        mesh = read_msh(tmp)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return mesh


def _sphere_size(res: Resolution, centre: float, gap_planes: Sequence[float] = (0.0,)) -> SizeFn:
    """Size field for a unit sphere centred at (0, centre) facing the planes z = gap_planes.

    Size = min(h_sphere + growth * d_sphere, h(r)/(n_gap + 0.3) in the gap column; the 0.3
    makes gmsh round the axis segment to exactly n_gap elements), with the local gap
    ``h(r) = |centre - plane| - sqrt(1 - r^2)``.
    """

    # The callback runs ~1e5 times per mesh: locals and plain comparisons instead of
    # function calls (the same arithmetic, so the same sizes to the last bit).
    h0, gr, ng = res.h_sphere, res.growth, res.n_gap + 0.3
    cols = tuple((min(zp, centre) - ZTOL, max(zp, centre) + ZTOL, abs(centre - zp))
                 for zp in gap_planes)
    hypot, sqrt = math.hypot, math.sqrt

    def size(r: float, z: float) -> float:
        d = hypot(r, z - centre) - 1.0
        s = h0 + gr * (d if d >= 0.0 else -d)
        if r < 1.0:
            root = sqrt(1.0 - r * r)
            for lo, hi, dz in cols:
                # between the plane and the centre; the tolerance keeps points gmsh puts a
                # rounding error below the plane (z = -1e-36 on a bridge's wall) in the column
                if lo <= z <= hi:
                    h = dz - root
                    g = (h if h > 0.0 else 0.0) / ng
                    if g < s:
                        s = g
        return s

    return size


def _grown(res: Resolution, d: float) -> float:
    """Size at distance d (units of R) from the sphere: ``h_sphere + growth d``."""
    return res.h_sphere + res.growth * d


def _check_gap(gap: float) -> None:
    if not (isinstance(gap, int | float) and math.isfinite(gap) and 1e-6 <= gap <= 1e3):
        raise InputError(f"mesh gap S/R = {gap!r}; allowed: [1e-6, 1e3]")


# ---- geometries -------------------------------------------------------------------------


def sphere_wall(gap: float, res: Resolution, plane: str = "wall") -> meshio.Mesh:
    """Unit sphere at surface gap ``gap`` (= S/R) above the plane z = 0, in a liquid.

    Domain: the quarter disc r, z >= 0 of radius L = ``res.far`` about the origin, minus the
    sphere centred at (0, 1 + gap). Boundaries ``axis``, ``plane`` (``"wall"`` for a no-slip
    wall, ``"symmetry"`` for the mid-plane of two equal spheres), ``sphere``, ``far``.
    """
    _check_gap(gap)
    if plane not in ("wall", "symmetry"):
        raise InputError(f"plane = {plane!r}; allowed: 'wall', 'symmetry'")
    c = 1.0 + gap
    L = max(res.far, 100.0 * (c + 1.0))
    with _Gmsh("sphere_wall") as gmsh:
        g = gmsh.model.geo
        o, pw, pf = g.addPoint(0, 0, 0), g.addPoint(L, 0, 0), g.addPoint(0, L, 0)
        pc, pb, pt = g.addPoint(0, c, 0), g.addPoint(0, c - 1.0, 0), g.addPoint(0, c + 1.0, 0)
        pe = g.addPoint(1.0, c, 0)
        wall = g.addLine(o, pw)
        far = g.addCircleArc(pw, o, pf)
        ax_top = g.addLine(pf, pt)
        s_up = g.addCircleArc(pt, pc, pe)
        s_lo = g.addCircleArc(pe, pc, pb)
        ax_gap = g.addLine(pb, o)
        loop = g.addCurveLoop([wall, far, ax_top, s_up, s_lo, ax_gap])
        surf = g.addPlaneSurface([loop])
        groups = {"axis": [ax_top, ax_gap], plane: [wall], "sphere": [s_up, s_lo], "far": [far]}
        return _mesh_and_read(gmsh, _sphere_size(res, c), groups, surf)


def sphere_sphere(gap: float, res: Resolution, radius2: float = 1.0) -> meshio.Mesh:
    """Unit sphere above a sphere of radius ``radius2`` (= R2/R) at surface gap ``gap``.

    The gap's mid-point is the origin: the upper sphere's centre is at z = 1 + gap/2, the
    lower one's at z = -(radius2 + gap/2) (equal spheres: +-(1 + gap/2)). Domain: the half
    disc r >= 0 of radius L = ``res.far`` minus both spheres. Boundaries ``axis``,
    ``sphere`` (upper, radius 1), ``sphere2`` (lower), ``far``. The plane z = 0 is not a
    boundary: this is the full problem (for equal spheres the check on the symmetric half
    domain). Size field: :func:`_two_sphere_size`.
    """
    _check_gap(gap)
    a2 = float(radius2)
    if not (math.isfinite(a2) and 0.05 <= a2 <= 20.0):
        raise InputError(f"mesh radius ratio R2/R = {radius2!r}; allowed: [0.05, 20]")
    c1, c2 = 1.0 + 0.5 * gap, -(a2 + 0.5 * gap)
    L = max(res.far, 100.0 * max(c1 + 1.0, a2 - c2))
    with _Gmsh("sphere_sphere") as gmsh:
        g = gmsh.model.geo
        o = g.addPoint(0, 0, 0)
        pfb, pw, pft = g.addPoint(0, -L, 0), g.addPoint(L, 0, 0), g.addPoint(0, L, 0)
        pc1, pb1, pt1, pe1 = (g.addPoint(0, c1, 0), g.addPoint(0, c1 - 1, 0),
                              g.addPoint(0, c1 + 1, 0), g.addPoint(1, c1, 0))
        pc2, pb2, pt2, pe2 = (g.addPoint(0, c2, 0), g.addPoint(0, c2 - a2, 0),
                              g.addPoint(0, c2 + a2, 0), g.addPoint(a2, c2, 0))
        far1 = g.addCircleArc(pfb, o, pw)
        far2 = g.addCircleArc(pw, o, pft)
        ax_top = g.addLine(pft, pt1)
        s1a, s1b = g.addCircleArc(pt1, pc1, pe1), g.addCircleArc(pe1, pc1, pb1)
        ax_gap = g.addLine(pb1, pt2)
        s2a, s2b = g.addCircleArc(pt2, pc2, pe2), g.addCircleArc(pe2, pc2, pb2)
        ax_bot = g.addLine(pb2, pfb)
        loop = g.addCurveLoop([far1, far2, ax_top, s1a, s1b, ax_gap, s2a, s2b, ax_bot])
        surf = g.addPlaneSurface([loop])
        groups = {"axis": [ax_top, ax_gap, ax_bot], "sphere": [s1a, s1b],
                  "sphere2": [s2a, s2b], "far": [far1, far2]}
        return _mesh_and_read(gmsh, _two_sphere_size(res, c1, c2, a2), groups, surf)


def _two_sphere_size(res: Resolution, c1: float, c2: float, a2: float) -> SizeFn:
    """Size field of a unit sphere at (0, c1) above a sphere of radius a2 at (0, c2).

    Size = min over the spheres of ``h_i + growth d_i`` (d_i the distance to sphere i,
    h_i = h_sphere min(1, a_i): a smaller sphere gets proportionally smaller elements), and
    in the gap column (r < min(1, a2), c2 <= z <= c1) ``h(r)/(2 n_gap + 0.6)`` with the
    local gap ``h(r) = c1 - sqrt(1 - r^2) - c2 - sqrt(a2^2 - r^2)``: n_gap elements per half
    gap, as for one sphere facing a plane (equal spheres: the same field as
    ``min`` of two :func:`_sphere_size`).
    """
    h2 = res.h_sphere * min(1.0, a2)
    r_col = min(1.0, a2)
    h0, gr, ng = res.h_sphere, res.growth, 2 * res.n_gap + 0.6
    lo, hi, a22 = c2 - ZTOL, c1 + ZTOL, a2 * a2
    hypot, sqrt = math.hypot, math.sqrt

    def size(r: float, z: float) -> float:  # locals only: see _sphere_size
        d1 = hypot(r, z - c1) - 1.0
        d2 = hypot(r, z - c2) - a2
        s = h0 + gr * (d1 if d1 >= 0.0 else -d1)
        t = h2 + gr * (d2 if d2 >= 0.0 else -d2)
        if t < s:
            s = t
        if r < r_col and lo <= z <= hi:
            rr = r * r
            h = c1 - sqrt(1.0 - rr) - c2 - sqrt(a22 - rr)
            g = (h if h > 0.0 else 0.0) / ng
            if g < s:
                s = g
        return s

    return size


def isolated_sphere(res: Resolution) -> meshio.Mesh:
    """A unit sphere at the origin alone in a liquid: half disc of radius L = ``res.far``.

    Boundaries ``axis``, ``sphere``, ``far``. The Stokes drag 6 pi eta R v is the check.
    """
    L = res.far
    with _Gmsh("isolated_sphere") as gmsh:
        g = gmsh.model.geo
        o = g.addPoint(0, 0, 0)
        pfb, pw, pft = g.addPoint(0, -L, 0), g.addPoint(L, 0, 0), g.addPoint(0, L, 0)
        pb, pe, pt = g.addPoint(0, -1, 0), g.addPoint(1, 0, 0), g.addPoint(0, 1, 0)
        far1, far2 = g.addCircleArc(pfb, o, pw), g.addCircleArc(pw, o, pft)
        ax_top = g.addLine(pft, pt)
        s1, s2 = g.addCircleArc(pt, o, pe), g.addCircleArc(pe, o, pb)
        ax_bot = g.addLine(pb, pfb)
        surf = g.addPlaneSurface([g.addCurveLoop([far1, far2, ax_top, s1, s2, ax_bot])])
        groups = {"axis": [ax_top, ax_bot], "sphere": [s1, s2], "far": [far1, far2]}

        def size(r: float, z: float) -> float:
            return _grown(res, abs(math.hypot(r, z) - 1.0))

        return _mesh_and_read(gmsh, size, groups, surf)


def film_contact_radius(gap: float, film: float) -> float:
    """Radius r_c/R where a unit sphere at gap ``gap`` cuts the film surface z = ``film``."""
    return math.sqrt(1.0 - (1.0 + gap - film) ** 2)


def sphere_film(gap: float, film: float, res: Resolution, extent: float = 30.0) -> meshio.Mesh:
    """Unit sphere dipping into a liquid film of thickness ``film`` (= delta/R) on a wall.

    The free surface is flat, z = delta, outside the sphere; the sphere cuts it at
    r_c = sqrt(R^2 - (R + S - delta)^2) (needs S < delta <= S + R: the wetted cap is below the
    equator). Domain: 0 <= z <= delta between the axis, the wall, the wetted sphere cap,
    the free surface and a vertical far boundary at r = r_c + ``extent`` * delta.
    Boundaries ``axis``, ``wall``, ``sphere``, ``free_surface``, ``far``.

    Sizes: the sphere's field (:func:`_sphere_size`), at most ``h_film = delta/n_film`` in
    the film (growing by ``growth`` outwards from r_c), and graded down to the corner
    (r_c, delta) where the no-slip sphere meets the traction-free surface:
    ``max(film_corner delta, MIN_CORNER) + growth rho``, rho the distance from the corner.
    The corner is singular but integrable: in a wedge of angle alpha between a no-slip
    wall and a traction-free surface the velocity relative to the wall goes like
    rho^lambda, the stress like rho^(lambda - 1), with the smallest root lambda of the
    4 x 4 corner eigenproblem (Williams 1952, Moffatt 1964: stream function
    ``rho^(lambda+1) f(phi)``, f = f' = 0 on the wall, both tractions zero on the surface)
    lambda = 0.50-0.60 for alpha from pi (the stick-slip corner of Richardson 1970,
    lambda = 1/2) to pi/2;
    the film's corner has alpha = pi - asin(r_c/R). The dissipation is finite: no
    Huh-Scriven divergence, because the traction-free surface moves with the sphere at the
    corner (the fluid there has the sphere's velocity). The force error of elements of size
    h there is of order h^(2 lambda), about h: measured first order in ``film_corner``
    (1.09 and 1.03 at S = 0.95 delta, delta/R = 0.1 and 0.01, film_corner 8e-3 to 5e-4;
    0.7-0.8 where the corner's share is below the bulk's error, delta/R = 1e-3 or
    S = 0.5 delta); the grading costs a logarithmic number of extra elements.
    """
    _check_gap(gap)
    if not (gap < film <= gap + 1.0):
        raise InputError(f"film thickness delta/R = {film!r} at S/R = {gap!r}; allowed: "
                         "S < delta <= S + R (film reaches the sphere, cap below the equator)")
    c = 1.0 + gap
    rc = film_contact_radius(gap, film)
    rf = rc + extent * film
    with _Gmsh("sphere_film") as gmsh:
        g = gmsh.model.geo
        o, pw = g.addPoint(0, 0, 0), g.addPoint(rf, 0, 0)
        ptf, pcl = g.addPoint(rf, film, 0), g.addPoint(rc, film, 0)
        pc, pb = g.addPoint(0, c, 0), g.addPoint(0, c - 1.0, 0)
        wall, far = g.addLine(o, pw), g.addLine(pw, ptf)
        fs = g.addLine(ptf, pcl)
        sph = g.addCircleArc(pcl, pc, pb)
        ax = g.addLine(pb, o)
        surf = g.addPlaneSurface([g.addCurveLoop([wall, far, fs, sph, ax])])
        groups = {"axis": [ax], "wall": [wall], "sphere": [sph], "free_surface": [fs],
                  "far": [far]}
        base = _sphere_size(res, c)
        h_film = film / res.n_film
        h_corner = max(res.film_corner * film, MIN_CORNER)

        def size(r: float, z: float) -> float:
            d_cl = math.hypot(r - rc, z - film)  # graded towards the corner (r_c, delta)
            return min(base(r, z), h_film + res.growth * max(r - rc, 0.0),
                       h_corner + res.growth * d_cl)

        return _mesh_and_read(gmsh, size, groups, surf)


def sphere_bridge(gap: float, profile: np.ndarray, res: Resolution,
                  contact_size: float | None = None, radius2: float | None = None,
                  plane: str = "wall", n_width: int | None = None) -> meshio.Mesh:
    """Unit sphere joined to the wall z = 0 (or to a lower sphere) by a liquid bridge.

    Parameters
    ----------
    gap
        S/R.
    profile
        Meridian of the free surface, shape (n, 2), points (r, z) from the lower contact
        line (on the wall z = 0, or on the lower sphere of radius ``radius2`` centred at
        (0, -radius2)) to the upper contact line (on the unit sphere centred at
        (0, 1 + S/R)), e.g. the toroidal circle arc or the finite-element meniscus solver's
        profile. The curve is interpolated by a gmsh B-spline through the points.
    res
        Resolution; the size near the meniscus is ``h_sphere``.
    contact_size
        Element size at the two contact lines (units of R), growing by ``res.growth`` with
        the distance from them: resolves a Navier slip length there. ``None``: no grading.
    radius2
        R2/R of a lower sphere (its apex at the origin); ``None``: a plane.
    plane
        Name of the plane z = 0: ``"wall"`` or ``"symmetry"`` (the mid-plane of a bridge
        between two equal spheres, the profile starting at the neck).
    n_width
        At least this many elements across the bridge's local radius w(z) (the smallest r
        of the profile at the height z): the size is at most ``w(z)/n_width``, which only
        bites where w(z) < n_width times the other sizes, at a thin neck. ``None``: off.

    Boundaries ``axis``, ``sphere``, ``free_surface`` and ``wall`` (``symmetry``,
    ``sphere2``).
    """
    _check_gap(gap)
    if plane not in ("wall", "symmetry"):
        raise InputError(f"plane = {plane!r}; allowed: 'wall', 'symmetry'")
    prof = np.asarray(profile, dtype=float)
    c = 1.0 + gap
    if prof.ndim != 2 or prof.shape[1] != 2 or prof.shape[0] < 3 or not np.isfinite(prof).all():
        raise InputError("bridge profile: expected a finite (n >= 3, 2) array of (r, z)")
    if radius2 is None:
        if abs(prof[0, 1]) > 1e-9 or prof[0, 0] <= 0:
            raise InputError(f"bridge profile must start on the wall (z = 0, r > 0); got "
                             f"{prof[0]}")
    else:
        a2 = float(radius2)
        if not (math.isfinite(a2) and 0.05 <= a2 <= 20.0):
            raise InputError(f"mesh radius ratio R2/R = {radius2!r}; allowed: [0.05, 20]")
        if (abs(math.hypot(prof[0, 0], prof[0, 1] + a2) - a2) > 1e-6 * max(a2, 1.0)
                or prof[0, 0] <= 0 or prof[0, 1] <= -a2):
            raise InputError("bridge profile must start on the upper half of the lower "
                             f"sphere; got {prof[0]}")
    rs, zs = prof[-1]
    if abs(math.hypot(rs, zs - c) - 1.0) > 1e-6 or rs <= 0 or zs >= c:
        raise InputError(f"bridge profile must end on the lower half of the sphere; got {prof[-1]}")
    if np.any(prof[:, 0] <= 0):
        raise InputError("bridge profile crosses the axis (r <= 0)")
    if contact_size is not None and not (math.isfinite(contact_size)
                                         and 1e-9 <= contact_size <= 1.0):
        raise InputError(f"contact_size = {contact_size!r}; allowed: [1e-9, 1] R")
    if n_width is not None and not (isinstance(n_width, int) and 1 <= n_width <= 100):
        raise InputError(f"n_width = {n_width!r}; allowed: integer in [1, 100]")
    width = None if n_width is None else _width_table(prof, n_width)
    with _Gmsh("sphere_bridge") as gmsh:
        g = gmsh.model.geo
        o, pc, pb = g.addPoint(0, 0, 0), g.addPoint(0, c, 0), g.addPoint(0, c - 1.0, 0)
        pts = [g.addPoint(float(r), float(z), 0) for r, z in prof]
        fs = g.addSpline(pts)
        sph = g.addCircleArc(pts[-1], pc, pb)
        if radius2 is None:
            lower = g.addLine(o, pts[0])
            ax = g.addLine(pb, o)
            groups = {"axis": [ax], plane: [lower], "sphere": [sph], "free_surface": [fs]}
            base = _sphere_size(res, c)
        else:
            pc2 = g.addPoint(0, -a2, 0)
            lower = g.addCircleArc(o, pc2, pts[0])
            ax = g.addLine(pb, o)
            groups = {"axis": [ax], "sphere2": [lower], "sphere": [sph], "free_surface": [fs]}
            base = _two_sphere_size(res, c, -a2, a2)
        surf = g.addPlaneSurface([g.addCurveLoop([lower, fs, sph, ax])])
        if width is not None:
            base = _capped(base, *width)
        if contact_size is None:
            return _mesh_and_read(gmsh, lambda r, z: min(base(r, z), res.h_sphere), groups, surf)
        (r0, z0), (r1, z1) = prof[0], prof[-1]
        if plane == "symmetry":  # the meniscus meets the mid-plane: no contact line there
            r0, z0 = r1, z1

        hs, gr, hypot = res.h_sphere, res.growth, math.hypot

        def size(r: float, z: float) -> float:  # locals only: see _sphere_size
            d = hypot(r - r0, z - z0)
            d1 = hypot(r - r1, z - z1)
            if d1 < d:
                d = d1
            s = base(r, z)
            if hs < s:
                s = hs
            t = contact_size + gr * d
            return t if t < s else s

        return _mesh_and_read(gmsh, size, groups, surf)


def _width_table(prof: np.ndarray, n_width: int) -> tuple[list[float], list[float]]:
    """Heights and sizes ``w(z)/n_width`` (w the smallest r of the profile at height z, on
    the profile's own heights and where it crosses them), sorted by height."""
    r, z = prof[:, 0], prof[:, 1]
    zs = np.unique(z)
    lo, hi = np.minimum(z[:-1], z[1:]), np.maximum(z[:-1], z[1:])
    w = np.full(zs.size, np.inf)
    for k in range(r.size - 1):  # the segment's r at each height it spans
        m = (zs >= lo[k]) & (zs <= hi[k])
        if hi[k] > lo[k]:
            w[m] = np.minimum(w[m], r[k] + (r[k + 1] - r[k]) * (zs[m] - z[k]) / (z[k + 1] - z[k]))
        else:
            w[m] = np.minimum(w[m], min(r[k], r[k + 1]))
    return zs.tolist(), (w / n_width).tolist()


def _capped(size: SizeFn, zs: list[float], cap: list[float]) -> SizeFn:
    """``size`` capped by the piecewise-linear table (zs, cap) in z (held beyond its ends)."""
    n = len(zs)

    def capped(r: float, z: float) -> float:
        s = size(r, z)
        k = bisect_right(zs, z)
        if k == 0:
            c = cap[0]
        elif k == n:
            c = cap[-1]
        else:
            z0, z1 = zs[k - 1], zs[k]
            c = cap[k - 1] + (cap[k] - cap[k - 1]) * (z - z0) / (z1 - z0)
        return c if c < s else s

    return capped


def toroidal_bridge_profile(gap: float, half_angle: float, contact_angle: float = math.pi / 6,
                            n: int = 41) -> np.ndarray:
    """Circle-arc (toroidal) meridian of a bridge between a unit sphere and a plane.

    The arc meets the plane z = 0 at a right angle: it is the half of the equal-sphere
    toroidal bridge (Fisher 1926; form of Weigert & Ripperger 1999, PHYSICS.md section 2)
    with sphere-sphere gap a = 2S, half-filling angle b and contact angle theta on the sphere:
    ``r1 = (2R(1 - cos b) + a) / (2 cos(b + theta))``, ``r2 = R sin b + r1 (sin(b + theta) - 1)``,
    arc centre at (r2 + r1, 0). A non-zero theta keeps the corner between the sphere and the
    meniscus open (theta = 0 would be a cusp).

    Returns
    -------
    numpy.ndarray
        Points (r, z), shape (n, 2), from the plane (r2, 0) to the sphere contact point
        (sin b, 1 + S - cos b).
    """
    b, th = half_angle, contact_angle
    if not (0.0 < b < math.pi / 2 and 0.0 <= th and b + th < math.pi / 2):
        raise InputError(f"toroidal bridge: b = {b!r}, theta = {th!r}; allowed: 0 < b, "
                         "theta >= 0, b + theta < pi/2 rad")
    r1 = (2.0 * (1.0 - math.cos(b)) + 2.0 * gap) / (2.0 * math.cos(b + th))
    r2 = math.sin(b) + r1 * (math.sin(b + th) - 1.0)
    if r2 <= 0:
        raise InputError(f"toroidal bridge: neck radius {r2:.3g} <= 0 at b = {b:.3g} rad")
    t_end = math.pi / 2 - (b + th)
    t = np.linspace(0.0, t_end, n)
    return np.column_stack([r2 + r1 - r1 * np.cos(t), r1 * np.sin(t)])
