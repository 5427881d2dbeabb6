"""Quasi-static liquid bridge for the Stokes reference: domain, free-surface motion, force.

Model (Ca = eta v / sigma -> 0). At every instant the liquid occupies the static bridge of
the finite-element meniscus solver (:mod:`wetcontact.solver.meniscus`) at the current gap
and the fixed volume V; the free surface moves with the normal velocity of that family of
shapes, ``u_n = n . dX/dt = -v n . dX/dS`` (X(t; S) the meridian at normalised arc length
t, n the outward normal; any parametrisation gives the same normal velocity), with dX/dS at
fixed volume from the meniscus solver's implicit differentiation; it carries no tangential
traction. The contact lines move along the
solids at the speeds of the static family, which Navier slip on the solids (slip length b)
allows, at the price of the Huh-Scriven dissipation ``~ ln(1/b)``.

Force. To O(Ca) the meniscus deforms by a volume-conserving perturbation of the static
shape, whose first variation of the free energy E = sigma (A - cos th1 A1 - cos th2 A2)
vanishes (the static shape is an equilibrium at fixed V, Young's angle the natural
condition at the contact lines). The power balance of liquid and interfaces,
``F v = Phi + dE/dt``, then gives the O(Ca) (viscous) force on the sphere exactly as the
dissipation over the speed, ``F_visc = Phi / v``, with Phi the viscous plus Navier-slip
friction dissipation of the quasi-static flow: no pressure constant enters. The reaction
and the traction integral equal it when the pressure constant makes the free surface do
no net work (``int u_n sigma_nn dA = 0``), the choice made in
:func:`~wetcontact.solver.stokes.solve.solve_stokes`; they are returned as checks.

As S/R -> 0 the film between the solids dominates and the force tends to the lubrication
(Reynolds) force of the same wetted radius with the pressure released at the sphere's
contact line; the excess is the moving-contact-line dissipation, per line
``2 pi r_cl eta U_cl^2 f(theta) ln(L/b) / v``, ``f = 2 sin^2 theta/(theta - sin theta
cos theta)`` (Huh & Scriven 1971; Cox 1986), with U_cl the speed of the line along its
solid: :func:`contact_line_slope` gives the predicted ``dF/d ln(1/b)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.spatial import cKDTree

from wetcontact.errors import SolverError
from wetcontact.meshes.builders import Resolution, sphere_bridge
from wetcontact.meshes.io import to_skfem
from wetcontact.solver.meniscus import (
    Bridge,
    BridgeSolution,
    meniscus_profile,
    shape_rate,
    solve_volume,
)
from wetcontact.solver.stokes.solve import StokesSolution, solve_stokes

N_PROFILE = 801
"""Points of the resampled meridian (uniform in arc length) given to gmsh and the spline."""


@dataclass
class BridgeMotion:
    """The static meridian at one gap and its normal velocity, units of the sphere radius R.

    Attributes
    ----------
    t, profile, normal
        Normalised arc length (n,), points (n, 2) from the lower contact line to the
        sphere's, outward unit normals (2, n).
    normal_velocity
        ``u_n`` at the points per unit approach speed v = -dS/dt (lower solid at rest).
    contact_speed
        Speeds of the (lower, upper) contact line along its solid, relative to that solid,
        per unit approach speed (positive: the wetted zone grows).
    contact_radius
        r/R of the (lower, upper) contact line.
    flux, swept
        ``2 pi int u_n r ds`` over the free surface and ``pi r_c^2`` (r_c the sphere's
        contact radius): equal for a volume-conserving motion (a rigid sphere moving at unit
        speed sweeps the volume rate pi r_c^2 through its wetted cap).
    static
        The meniscus solution at the gap.
    """

    t: np.ndarray
    profile: np.ndarray
    normal: np.ndarray
    normal_velocity: np.ndarray
    contact_speed: tuple[float, float]
    contact_radius: tuple[float, float]
    flux: float
    swept: float
    static: BridgeSolution

    def surface(self):
        """The :data:`~wetcontact.solver.stokes.solve.SurfaceMotion` of this meridian: each node is
        projected on the cubic-spline meridian (nearest sample, then Newton in t)."""
        t = self.t
        if np.any(np.diff(t) <= 0):
            raise SolverError("bridge meridian: the parameter t must increase")
        sr, sz = CubicSpline(t, self.profile[:, 0]), CubicSpline(t, self.profile[:, 1])
        sun = CubicSpline(t, self.normal_velocity)
        tt = np.linspace(0.0, 1.0, 20 * t.size + 1)
        tree = cKDTree(np.column_stack([sr(tt), sz(tt)]))

        def motion(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            tp = tt[tree.query(xy.T)[1]]
            for _ in range(4):
                fr, fz = sr(tp) - xy[0], sz(tp) - xy[1]
                dr, dz = sr(tp, 1), sz(tp, 1)
                hess = dr * dr + dz * dz + fr * sr(tp, 2) + fz * sz(tp, 2)
                tp = np.clip(tp - (fr * dr + fz * dz) / hess, 0.0, 1.0)
            dr, dz = sr(tp, 1), sz(tp, 1)
            norm = np.hypot(dr, dz)
            return sun(tp), dz / norm, -dr / norm

        return motion


def _meridian(sol: BridgeSolution, radius: float) -> tuple[np.ndarray, np.ndarray]:
    prof = meniscus_profile(sol, n=N_PROFILE)
    return np.column_stack([prof["r"], prof["z"]]) / radius, prof["psi"]


def bridge_motion(bridge: Bridge, gap: float, volume: float) -> BridgeMotion | None:
    """Static bridge at ``gap`` (m) with ``volume`` (m^3) and its quasi-static normal velocity.

    ``u_n = -n . dX/dS`` per unit approach speed, with dX/dS at fixed volume from the
    meniscus solver's implicit differentiation (:func:`~wetcontact.solver.meniscus.shape_rate`).
    ``None`` when no bridge exists at ``gap`` (beyond rupture).
    """
    R = float(bridge.radius)
    sol = solve_volume(bridge, gap, volume)
    if not sol.exists:
        return None
    prof = meniscus_profile(sol, n=N_PROFILE)
    rate = shape_rate(sol, n=N_PROFILE)
    x0 = np.column_stack([prof["r"], prof["z"]]) / R
    psi = prof["psi"]
    dxds = np.column_stack([rate["dr"], rate["dz"]])  # d(X/ell)/d(S/ell), ell = R
    # tangent (cos psi, sin psi) from the lower line to the sphere's; liquid on the axis side
    normal = np.stack([np.sin(psi), -np.cos(psi)])
    un = -(normal[0] * dxds[:, 0] + normal[1] * dxds[:, 1])
    seg = np.hypot(*np.diff(x0, axis=0).T)
    rr = x0[:, 0]
    f = un * rr
    flux = 2 * math.pi * float(np.sum(0.5 * (f[1:] + f[:-1]) * seg))
    # contact lines: velocity -dX/dS relative to their solid, along the solid's tangent
    # pointing out of the wetted zone (the sphere moves at (0, -1), the lower solid rests)
    phi1 = sol.filling_angle1
    upper = float(np.dot(-dxds[-1] - [0.0, -1.0], [math.cos(phi1), math.sin(phi1)]))
    if bridge.radius2 is None:
        lower = float(-dxds[0, 0])
    else:
        phi2 = sol.filling_angle2
        lower = float(np.dot(-dxds[0], [math.cos(phi2), -math.sin(phi2)]))
    return BridgeMotion(t=rate["t"], profile=x0, normal=normal, normal_velocity=un,
                        contact_speed=(lower, upper), contact_radius=(rr[0], rr[-1]),
                        flux=flux, swept=math.pi * rr[-1] ** 2, static=sol)


def half_motion(motion: BridgeMotion, gap: float) -> BridgeMotion:
    """The upper half of a mirror-symmetric bridge between equal spheres (units R).

    The meridian is cut at the mid-plane z = S/2 (where it is vertical), shifted down by
    S/2, and the normal velocity is taken in the frame of the mid-plane, where the spheres
    move at -+ v/2: ``u_n + n_z / 2`` (``motion`` has the lower sphere at rest).
    """
    x, n, un = motion.profile, motion.normal, motion.normal_velocity
    zm = 0.5 * gap
    k = int(np.searchsorted(x[:, 1], zm))  # first point above the mid-plane
    if not (0 < k < x.shape[0]) or np.any(np.diff(x[:, 1]) <= 0):
        raise SolverError("bridge meridian: z is not increasing through the mid-plane")
    w = (zm - x[k - 1, 1]) / (x[k, 1] - x[k - 1, 1])
    cut = lambda a: (1 - w) * a[k - 1] + w * a[k]  # noqa: E731
    keep = slice(k + 1 if x[k, 1] - zm < 1e-9 else k, None)
    prof = np.vstack([[cut(x[:, 0]), 0.0], x[keep] - [0.0, zm]])
    nn = np.column_stack([[1.0, 0.0], n[:, keep]])
    u = np.concatenate([[cut(un)], un[keep]]) + 0.5 * nn[1]
    seg = np.hypot(*np.diff(prof, axis=0).T)
    t = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
    f = u * prof[:, 0]
    flux = 2 * math.pi * float(np.sum(0.5 * (f[1:] + f[:-1]) * seg))
    return BridgeMotion(t=t, profile=prof, normal=nn, normal_velocity=u,
                        contact_speed=motion.contact_speed,
                        contact_radius=motion.contact_radius, flux=flux,
                        swept=0.5 * motion.swept, static=motion.static)


def wedge_factor(theta: float) -> float:
    """Huh-Scriven wedge factor ``f = 2 sin^2 theta/(theta - sin theta cos theta)``.

    Dissipation per unit length of a contact line moving at U_cl along a solid, liquid
    wedge of angle theta under an inviscid gas: ``eta U_cl^2 f ln(L/b)`` (Huh & Scriven
    1971; Cox 1986, eq. for lambda = 0); ``f -> 3/theta`` as theta -> 0 (de Gennes 1985).
    """
    if not 0.0 < theta < math.pi:
        raise SolverError(f"wedge factor: theta = {theta!r} rad; allowed: (0, pi)")
    return 2.0 * math.sin(theta) ** 2 / (theta - math.sin(theta) * math.cos(theta))


def contact_line_slope(motion: BridgeMotion, theta_lower: float, theta_upper: float) -> float:
    """Predicted ``dF/d ln(1/b)`` (units eta R v) of the bridge force from its two moving
    contact lines: ``sum 2 pi r_cl U_cl^2 f(theta)`` (:func:`wedge_factor`), the slip
    length b the same on both solids."""
    (r0, r1), (u0, u1) = motion.contact_radius, motion.contact_speed
    return 2 * math.pi * (r0 * u0**2 * wedge_factor(theta_lower)
                          + r1 * u1**2 * wedge_factor(theta_upper))


@dataclass
class BridgeFlow:
    """Stokes flow in a quasi-static bridge (units R = eta = v = 1).

    ``force`` is the viscous force on the sphere (positive pushing apart) from the
    dissipation, ``Phi / v``; ``solution.force_reaction`` and ``solution.force_traction``
    are the two checks (pressure constant: no net work by the free surface).
    """

    force: float
    solution: StokesSolution
    motion: BridgeMotion
    gap_elements: int


def solve_bridge(bridge: Bridge, gap: float, volume: float, slip: tuple[float, float],
                 res: Resolution, contact_size: float, intorder: int = 4,
                 symmetric: bool = False) -> BridgeFlow | None:
    """Viscous force of a quasi-static bridge at ``gap`` (m): meniscus, mesh, Stokes.

    Parameters
    ----------
    bridge
        The solids and liquid (SI), sphere of radius ``bridge.radius`` on top.
    gap, volume
        S (m) and V (m^3).
    slip
        Navier slip lengths (m, > 0) on the sphere and on the lower solid.
    res
        Mesh resolution (units R).
    contact_size
        Element size at the contact lines (units R).
    symmetric
        Solve a mirror-symmetric bridge (equal spheres, contact angles and slip lengths) on
        its upper half: the mid-plane is a shear-free symmetry plane, the sphere moves at
        v/2 (:func:`half_motion`); the force is the same, at half the cost.

    Returns ``None`` past rupture (no bridge: no force).
    """
    from wetcontact.solver.stokes.solve import gap_elements

    R = float(bridge.radius)
    motion = bridge_motion(bridge, gap, volume)
    if motion is None:
        return None
    q = None if bridge.radius2 is None else bridge.radius2 / R
    s = gap / R
    if symmetric:
        if not (q == 1.0 and bridge.contact_angle1 == bridge.contact_angle2
                and slip[0] == slip[1]):
            raise SolverError("symmetric bridge: needs equal spheres, contact angles and "
                              "slip lengths")
        half = half_motion(motion, s)
        mesh = to_skfem(sphere_bridge(0.5 * s, half.profile, res, contact_size=contact_size,
                                      plane="symmetry"))
        sol = solve_stokes(mesh, {"sphere": -0.5}, intorder=intorder,
                           slip={"sphere": slip[0] / R}, surface=half.surface())
        return BridgeFlow(force=sol.force_dissipation, solution=sol, motion=half,
                          gap_elements=gap_elements(mesh, 0.0, 0.5 * s))
    mesh = to_skfem(sphere_bridge(s, motion.profile, res, contact_size=contact_size,
                                  radius2=q))
    lower = "wall" if q is None else "sphere2"
    sol = solve_stokes(mesh, {"sphere": -1.0, lower: 0.0} if q is not None else {"sphere": -1.0},
                       intorder=intorder,
                       slip={"sphere": slip[0] / R, lower: slip[1] / R},
                       surface=motion.surface())
    return BridgeFlow(force=sol.force_dissipation, solution=sol, motion=motion,
                      gap_elements=gap_elements(mesh, 0.0, s))
