"""The moving liquid domain of a bridge on a sphere: an ALE mesh of second-order triangles.

Units R = 1 (the upper sphere's radius). The sphere's centre is at ``(0, 1 + S)``; the
lower solid is the wall z = 0, the mid-plane of two equal spheres (``plane =
"symmetry"``) or a lower sphere of radius ``R2`` (``MeshOptions.radius2``, units R)
centred at ``(0, -R2)``, its apex at the origin. The boundary is four named chains of P2
edges (:func:`chain`): ``free_surface`` from the lower solid's contact line to the
sphere's, ``sphere`` from its apex on the axis to its contact line, the lower solid
(``wall``, ``symmetry`` or ``sphere2``; the attribute ``wall``) from the origin to its
contact line, ``axis`` from the origin to the apex.

The state of the bridge is the free surface alone (Stokes flow has no memory): every other
node follows it. Solid nodes keep their reference fractions of the wetted arc (wall: r/r_w;
spheres: angle from the apex over the filling angle; axis: z/S), on the exact solids;
interior nodes follow by a harmonic extension of the boundary displacement from the
reference mesh, stiffened by 1/area so that the small contact-line elements move rigidly
(Johnson & Tezduyar 1994). The extension matrix is factorised once per reference mesh.

Volume (the meniscus solver's definition, exact solids): ``V = pi int_Gamma r^2 dz -
V_cap(phi) - R2^3 V_cap(phi_2)``, ``V_cap = pi (1 - cos phi)^2 (2 + cos phi)/3`` the unit
sphere's cap below its contact line (phi its filling angle) and the lower sphere's above
its line (phi_2; none on a plane), evaluated exactly on the P2 free surface (3-point Gauss,
the integrand is a polynomial of degree 5).

Meshes come from gmsh (:func:`~wetcontact.meshes.builders.sphere_bridge`, with ``n_width``
elements across the local radius at a thin neck) in a worker process (:class:`_Mesher`):
one that takes longer than ``MeshOptions.timeout`` is abandoned with a SolverError.
"""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
from dataclasses import dataclass, field
from multiprocessing.connection import Connection

import numpy as np
import scipy.sparse.linalg as spla
from scipy.interpolate import CubicSpline
from skfem import Basis, BilinearForm, ElementTriP2, MeshTri2
from skfem.helpers import dot, grad

from wetcontact.errors import SolverError
from wetcontact.meshes.builders import Resolution, sphere_bridge
from wetcontact.meshes.io import to_skfem

STIFFENING = 1.0
"""Exponent chi of the mesh-motion stiffening (A_max/A)^chi."""

_GX, _GW = np.polynomial.legendre.leggauss(3)
GAUSS3 = (0.5 * (_GX + 1.0), 0.5 * _GW)
"""3-point Gauss rule on [0, 1] (exact to degree 5)."""


def p2_shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P2 shape functions on [0, 1] with nodes (start, end, middle) and their derivatives,
    each of shape (3, len(xi))."""
    xi = np.asarray(xi, dtype=float)
    n = np.stack([(1 - xi) * (1 - 2 * xi), xi * (2 * xi - 1), 4 * xi * (1 - xi)])
    dn = np.stack([4 * xi - 3, 4 * xi - 1, 4 - 8 * xi])
    return n, dn


def chain(mesh: MeshTri2, name: str, start: int) -> np.ndarray:
    """Nodes of the boundary ``name`` in order from its end vertex ``start``: vertex,
    mid-edge node, vertex, ... (2N + 1 node indices; a mid-edge node of facet f is
    ``nvertices + f``, the order of ``mesh.doflocs``)."""
    facets = mesh.boundaries[name]
    ends = mesh.facets[:, facets]
    nxt: dict[int, list[tuple[int, int]]] = {}
    for k in range(facets.size):
        a, b = int(ends[0, k]), int(ends[1, k])
        nxt.setdefault(a, []).append((b, int(facets[k])))
        nxt.setdefault(b, []).append((a, int(facets[k])))
    if start not in nxt or len(nxt[start]) != 1:
        raise SolverError(f"boundary '{name}': vertex {start} is not one of its ends")
    out, prev, cur = [start], -1, start
    for _ in range(facets.size):
        (b, f), = [(b, f) for b, f in nxt[cur] if f != prev]
        out += [mesh.nvertices + f, b]
        prev, cur = f, b
    if len(out) != 2 * facets.size + 1:
        raise SolverError(f"boundary '{name}' is not one open chain")
    return np.array(out, dtype=np.int64)


def edges_of(nodes: np.ndarray) -> np.ndarray:
    """(N, 3) edges (start, end, middle) of a chain of 2N + 1 nodes."""
    return np.column_stack([nodes[0:-1:2], nodes[2::2], nodes[1::2]])


def sphere_angle(xy: np.ndarray, gap: float) -> np.ndarray:
    """Angle from the sphere's apex of points (2, n) on (or near) the sphere."""
    return np.arctan2(xy[0], 1.0 + gap - xy[1])


def on_sphere(angle: np.ndarray, gap: float) -> np.ndarray:
    """Points (2, n) of the sphere at ``angle`` from its apex."""
    return np.stack([np.sin(angle), 1.0 + gap - np.cos(angle)])


def lower_angle(xy: np.ndarray, radius2: float) -> np.ndarray:
    """Angle from the lower sphere's apex (the origin; radius ``radius2``, centre
    ``(0, -radius2)``) of points (2, n) on (or near) it."""
    return np.arctan2(xy[0], radius2 + xy[1])


def on_lower(angle: np.ndarray, radius2: float) -> np.ndarray:
    """Points (2, n) of the lower sphere of radius ``radius2`` at ``angle`` from its apex."""
    return radius2 * np.stack([np.sin(angle), np.cos(angle) - 1.0])


def cap_volume(phi: float) -> float:
    """Volume of the unit sphere's cap of half-angle phi."""
    c = math.cos(phi)
    return math.pi * (1 - c) ** 2 * (2 + c) / 3.0


def surface_volume(xs: np.ndarray, gap: float, radius2: float | None = None) -> float:
    """Liquid volume under the free surface ``xs`` (2, 2N + 1) (module docstring; ``radius2``
    the lower sphere's radius, ``None`` a plane)."""
    n, dn = p2_shape(GAUSS3[0])
    e = np.stack([xs[:, 0:-1:2], xs[:, 2::2], xs[:, 1::2]], axis=1)  # (2, 3, N)
    r = np.einsum("kq,kn->nq", n, e[0])
    dz = np.einsum("kq,kn->nq", dn, e[1])
    v = math.pi * float(np.sum(r * r * dz * GAUSS3[1]))
    if radius2 is not None:
        v -= radius2**3 * cap_volume(float(lower_angle(xs[:, :1], radius2)[0]))
    return v - cap_volume(float(sphere_angle(xs[:, -1:], gap)[0]))


def surface_normals(xs: np.ndarray) -> np.ndarray:
    """Outward unit normals (2, 2N + 1) at the nodes of a free-surface chain (vertices: the
    mean of the two edges' tangents; the tangent runs from the wall to the sphere and the
    liquid is on the axis side, so n = (t_z, -t_r))."""
    t = np.zeros_like(xs)
    e = np.stack([xs[:, 0:-1:2], xs[:, 2::2], xs[:, 1::2]], axis=1)
    _, d0 = p2_shape(np.array([0.0, 0.5, 1.0]))
    tang = np.einsum("kq,ckn->cnq", d0, e)  # (2, N, 3)
    t[:, 1::2] = tang[:, :, 1]
    t[:, 0:-1:2] += tang[:, :, 0]
    t[:, 2::2] += tang[:, :, 2]
    t /= np.hypot(t[0], t[1])
    return np.stack([t[1], -t[0]])


def neck_point(xs: np.ndarray) -> tuple[float, float, int, float]:
    """(radius, height, element, xi) of the narrowest point of the P2 free surface: the
    minimum of r along each quadratic edge ``k`` (nodes 2k, 2k + 2, midpoint 2k + 1), at the
    local coordinate ``xi`` in [0, 1] of that edge."""
    e = np.stack([xs[:, 0:-1:2], xs[:, 2::2], xs[:, 1::2]], axis=1)  # (2, 3, N)
    # r(xi) = a + b xi + c xi^2 from the node values at 0, 1, 1/2
    r0, r1, rm = e[0]
    b, c = 4 * rm - 3 * r0 - r1, 2 * r0 + 2 * r1 - 4 * rm
    with np.errstate(divide="ignore", invalid="ignore"):
        xs_ = np.where(c > 0, np.clip(-b / (2 * c), 0.0, 1.0), 0.0)
    best = (math.inf, 0.0, 0, 0.0)
    for xi in (xs_, np.zeros_like(r0), np.ones_like(r0)):
        n, _ = p2_shape(xi)
        rr = np.sum(n * e[0], axis=0)
        k = int(np.argmin(rr))
        if rr[k] < best[0]:
            best = (float(rr[k]), float(np.sum(n[:, k] * e[1][:, k])), k, float(xi[k]))
    return best


def neck(xs: np.ndarray) -> tuple[float, float]:
    """(radius, height) of the narrowest point of the P2 free surface (:func:`neck_point`)."""
    return neck_point(xs)[:2]


def contact_angles(xs: np.ndarray, gap: float, radius2: float | None = None
                   ) -> tuple[float, float]:
    """Contact angles (rad, through the liquid) of the P2 surface ``xs`` at the lower solid
    (the wall, or the sphere of radius ``radius2``) and at the sphere at ``gap``, from the
    end tangents of its first and last quadratic edges."""
    _, d0 = p2_shape(np.array([0.0]))
    _, d1 = p2_shape(np.array([1.0]))
    t0 = np.stack([xs[:, 0], xs[:, 2], xs[:, 1]], axis=1) @ d0[:, 0]
    t1 = np.stack([xs[:, -3], xs[:, -1], xs[:, -2]], axis=1) @ d1[:, 0]
    t0, t1 = t0 / np.hypot(*t0), t1 / np.hypot(*t1)
    phi = float(sphere_angle(xs[:, -1:], gap)[0])
    cs = float(t1[0] * math.cos(phi) + t1[1] * math.sin(phi))
    a2 = 0.0 if radius2 is None else float(lower_angle(xs[:, :1], radius2)[0])
    cw = -float(t0[0] * math.cos(a2) - t0[1] * math.sin(a2))
    return math.acos(min(1.0, max(-1.0, cw))), math.acos(min(1.0, max(-1.0, cs)))


def redistribute(xs: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """Nodes moved along the curve through ``xs`` (a cubic spline in chord length) to the
    given fractions of its chord length; the ends stay where they are."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xs, axis=1)))])
    sr, sz = CubicSpline(s, xs[0]), CubicSpline(s, xs[1])
    t = fractions * s[-1]
    out = np.stack([sr(t), sz(t)])
    out[:, 0], out[:, -1] = xs[:, 0], xs[:, -1]
    return out


def profile_of(xs: np.ndarray, n: int = 801) -> np.ndarray:
    """The free surface resampled at ``n`` points uniform in chord length, shape (n, 2)."""
    return redistribute(xs, np.linspace(0.0, 1.0, n)).T


def dense_profile(xs: np.ndarray) -> np.ndarray:
    """The free surface (n, 2) through its own nodes and a point between each two (the
    spline of :func:`redistribute`): a remesh keeps the nodes' local resolution."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xs, axis=1)))])
    f = s / s[-1]
    return redistribute(xs, np.sort(np.concatenate([f, 0.5 * (f[1:] + f[:-1])]))).T


def correct_volume(xs: np.ndarray, gap: float, volume: float, tol: float = 1e-13,
                   radius2: float | None = None) -> tuple[np.ndarray, float]:
    """Shift the free-surface nodes along their normals by ``d sin(pi f)`` (f the chord
    fraction; the contact lines stay on their solids and the surface keeps its angles there)
    with the one d that makes the volume ``volume`` (secant iteration; V is a cubic in d;
    ``radius2`` the lower sphere's, :func:`surface_volume`). Returns the surface and d.
    """
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xs, axis=1)))])
    n = surface_normals(xs) * np.sin(math.pi * s / s[-1])
    n[:, 0] = n[:, -1] = 0.0

    def vol(d: float) -> float:
        return surface_volume(xs + d * n, gap, radius2) - volume

    area = 2 * math.pi * float(np.sum(xs[0] * np.hypot(*np.gradient(xs, axis=1))
                                      * np.hypot(n[0], n[1])))
    d0, f0 = 0.0, vol(0.0)
    d1 = -f0 / area
    for _ in range(30):
        f1 = vol(d1)
        if abs(f1) <= tol * volume or f1 == f0:
            break
        d0, d1, f0 = d1, d1 - f1 * (d1 - d0) / (f1 - f0), f1
    else:
        raise SolverError(f"volume correction did not converge ({f1 / volume:.2e} relative)")
    return xs + d1 * n, d1


# ---- element shape ------------------------------------------------------------------

_SAMPLE = np.array([[0, 0], [1, 0], [0, 1], [0.5, 0], [0.5, 0.5], [0, 0.5], [1 / 3, 1 / 3]],
                   dtype=float)


def _p2_det(mesh: MeshTri2, x: np.ndarray) -> np.ndarray:
    """Jacobian determinant (n_elements, 7) of the isoparametric map with nodes ``x`` at
    the vertices, edge midpoints and centroid of the reference triangle."""
    t, t2f, nv = mesh.t, mesh.t2f, mesh.nvertices
    nodes = np.vstack([t, nv + t2f])  # local order: v0, v1, v2, e01, e12, e02
    xe = x[:, nodes]  # (2, 6, nel)
    lam = np.stack([1 - _SAMPLE[:, 0] - _SAMPLE[:, 1], _SAMPLE[:, 0], _SAMPLE[:, 1]])
    dl = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])  # d lambda_i / d(xi, eta)
    dN = np.zeros((6, 2, _SAMPLE.shape[0]))
    for i in range(3):
        dN[i] = np.outer(dl[i], 4 * lam[i] - 1)
    for k, (a, b) in enumerate(((0, 1), (1, 2), (0, 2))):
        dN[3 + k] = 4 * (np.outer(dl[a], lam[b]) + np.outer(dl[b], lam[a]))
    J = np.einsum("cke,kdq->cdeq", xe, dN)  # (2, 2, nel, nq)
    return J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]


def element_quality(mesh: MeshTri2, x: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per element: the vertex triangle's shape ``4 sqrt(3) A / sum l^2`` (1 equilateral, 0
    degenerate) and the curvature ratio ``min det J / (2 A)`` of the P2 map (1 for straight
    edges; <= 0 an inverted element)."""
    x = mesh.doflocs if x is None else x
    a, b, c = (x[:, mesh.t[i]] for i in range(3))
    area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    l2 = sum(np.sum((p - q) ** 2, axis=0) for p, q in ((a, b), (b, c), (c, a)))
    shape = 4 * math.sqrt(3) * area / l2
    with np.errstate(divide="ignore", invalid="ignore"):
        curv = np.min(_p2_det(mesh, x), axis=1) / (2 * area)
    return shape, np.where(area > 0, curv, -1.0)


# ---- gmsh in a worker process --------------------------------------------------------


def serve(fd_in: int, fd_out: int) -> None:
    """Worker loop (run by :class:`_Mesher` in its own interpreter): build each requested
    bridge mesh and send it back, or the error."""
    conn_in, conn_out = Connection(fd_in, writable=False), Connection(fd_out, readable=False)
    while True:
        try:
            args, kwargs = conn_in.recv()
        except EOFError:
            return
        try:
            conn_out.send(("ok", sphere_bridge(*args, **kwargs)))
        except Exception as exc:  # noqa: BLE001 - any gmsh failure goes back as a message
            conn_out.send(("error", f"{type(exc).__name__}: {exc}"))


class _Mesher:
    """gmsh in a persistent worker process (a fresh interpreter running :func:`serve`), so
    that a mesh that does not finish within ``timeout`` seconds is abandoned (the worker
    is killed; the next call starts a new one) and reported as a
    :class:`~wetcontact.errors.SolverError`, never a hang."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None

    def _start(self) -> None:
        to_child, self.send_end = os.pipe()
        self.recv_end, from_child = os.pipe()
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        code = f"from {__name__} import serve; serve({to_child}, {from_child})"
        self.proc = subprocess.Popen([sys.executable, "-c", code], env=env,
                                     pass_fds=(to_child, from_child),
                                     stdout=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
        os.close(to_child)
        os.close(from_child)
        self.send = Connection(self.send_end, readable=False)
        self.recv = Connection(self.recv_end, writable=False)

    def stop(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.send.close()
            self.recv.close()
        self.proc = None

    def __call__(self, timeout: float, *args, **kwargs):
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        self.send.send((args, kwargs))
        if not self.recv.poll(timeout):
            self.stop()
            raise SolverError(f"gmsh did not finish within {timeout:g} s (the worker was "
                              "stopped)")
        try:
            status, out = self.recv.recv()
        except EOFError:
            self.stop()
            raise SolverError("the gmsh worker died") from None
        if status != "ok":
            raise SolverError(f"gmsh failed: {out}")
        return out


MESHER = _Mesher()
"""The module's gmsh worker (:class:`_Mesher`)."""


# ---- the domain -----------------------------------------------------------------------


RADIUS2_RANGE = (0.05, 20.0)
"""R2/R of a lower sphere the mesh builder takes."""


@BilinearForm
def _stiffened_laplace(u, v, w):
    return w["k"] * dot(grad(u), grad(v))


@dataclass(frozen=True)
class MeshOptions:
    """Element sizes of a bridge mesh (units R).

    Attributes
    ----------
    h_surface
        Size on the free surface and in the bulk away from the contact lines; capped at
        ``neck_radius / n_neck`` at every (re)meshing.
    contact_size
        Size at the two contact lines (resolves the slip length).
    growth
        Size growth with the distance from a contact line.
    n_gap
        Elements across the gap along the axis.
    n_neck
        Elements across the bridge's local radius, wherever that radius is below
        ``n_neck h_surface`` (the neck): the builder's ``n_width``.
    timeout
        Seconds gmsh may take for one mesh (:class:`_Mesher`); past it the mesh fails.
    plane
        ``"wall"``: a sphere on a wall; ``"symmetry"``: the upper half of a bridge between
        two equal spheres (the plane z = 0 is the mid-plane, shear-free, and the surface
        meets it at right angles: no contact line there; gap and volume are the half's).
    radius2
        R2/R of a lower sphere (its apex at the origin, a solid with slip and a contact
        line like the wall) instead of the plane; ``None``: the plane.
    """

    h_surface: float = 0.01
    contact_size: float = 1e-3
    growth: float = 0.15
    n_gap: int = 4
    n_neck: int = 8
    timeout: float = 60.0
    plane: str = "wall"
    radius2: float | None = None

    def __post_init__(self) -> None:
        if self.radius2 is not None:
            a2 = self.radius2
            if not (math.isfinite(a2) and RADIUS2_RANGE[0] <= a2 <= RADIUS2_RANGE[1]):
                raise SolverError(f"stokes-dynamic: radius2 = {a2!r} R; allowed: "
                                  f"[{RADIUS2_RANGE[0]:g}, {RADIUS2_RANGE[1]:g}] or None")
            if self.plane != "wall":
                raise SolverError(f"stokes-dynamic: plane = {self.plane!r} with a lower sphere "
                                  "(radius2); allowed: 'wall'")

    def resolution(self) -> Resolution:
        """The builder's :class:`~wetcontact.meshes.builders.Resolution`."""
        return Resolution(n_gap=self.n_gap, h_sphere=self.h_surface, growth=self.growth,
                          far=1e3)


@dataclass
class Domain:
    """A bridge mesh with its boundary chains and the map from a free surface to the nodes.

    Attributes
    ----------
    mesh
        The current mesh (``doflocs`` moved, connectivity and boundaries of the reference).
    gap
        S/R of the current mesh.
    surface, sphere, wall, axis
        Node chains (:func:`chain`); ``wall`` is the lower solid: the plane z = 0, named
        ``plane`` (``"wall"`` or ``"symmetry"``, :class:`MeshOptions`), or the lower sphere
        (``"sphere2"``).
    reference
        Node positions (2, n) of the reference mesh (the last one gmsh made).
    fractions
        Per chain, the reference fraction of each node (free surface: chord length; wall:
        r/r_w; spheres: angle/filling angle; axis: z/S).
    radius2
        R2/R of the lower sphere; ``None``: the plane.
    """

    mesh: MeshTri2
    gap: float
    surface: np.ndarray
    sphere: np.ndarray
    wall: np.ndarray
    axis: np.ndarray
    reference: np.ndarray
    fractions: dict[str, np.ndarray]
    quality0: tuple[np.ndarray, np.ndarray]
    plane: str = "wall"
    radius2: float | None = None
    _extension: tuple = field(repr=False, default=())

    @classmethod
    def from_profile(cls, gap: float, profile: np.ndarray, opts: MeshOptions) -> Domain:
        """Mesh the bridge whose free surface is ``profile`` (n, 2), from the wall's contact
        line (z = 0) to a point of the sphere, by gmsh (:func:`~wetcontact.meshes.builders.
        sphere_bridge`)."""
        prof = np.asarray(profile, dtype=float)
        mesh = MESHER(opts.timeout, gap, prof, opts.resolution(), contact_size=opts.contact_size,
                      n_width=opts.n_neck, plane=opts.plane, radius2=opts.radius2)
        return cls.on_mesh(to_skfem(mesh), gap, opts.radius2)

    @classmethod
    def on_mesh(cls, mesh: MeshTri2, gap: float, radius2: float | None = None) -> Domain:
        x = mesh.doflocs
        fs = mesh.facets[:, mesh.boundaries["free_surface"]]
        ends = [v for v in np.unique(fs) if np.count_nonzero(fs == v) == 1]
        low = min(ends, key=lambda v: x[1, v])
        high = max(ends, key=lambda v: x[1, v])
        ax = mesh.facets[:, mesh.boundaries["axis"]]
        ax_ends = [v for v in np.unique(ax) if np.count_nonzero(ax == v) == 1]
        origin = min(ax_ends, key=lambda v: x[1, v])
        apex = max(ax_ends, key=lambda v: x[1, v])
        surface = chain(mesh, "free_surface", int(low))
        sphere = chain(mesh, "sphere", int(apex))
        plane = "symmetry" if "symmetry" in mesh.boundaries else "wall"
        wall = chain(mesh, "sphere2" if radius2 is not None else plane, int(origin))
        axis = chain(mesh, "axis", int(origin))
        if sphere[-1] != high or wall[-1] != low or axis[-1] != apex:
            raise SolverError("bridge mesh: the boundary chains do not meet at the contact "
                              "lines and the axis")
        xs = x[:, surface]
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xs, axis=1)))])
        ang = sphere_angle(x[:, sphere], gap)
        lower = x[0, wall] if radius2 is None else lower_angle(x[:, wall], radius2)
        frac = {"surface": s / s[-1], "sphere": ang / ang[-1], "wall": lower / lower[-1],
                "axis": x[1, axis] / gap}
        dom = cls(mesh=mesh, gap=gap, surface=surface, sphere=sphere, wall=wall, axis=axis,
                  plane=plane, radius2=radius2,
                  reference=x.copy(), fractions=frac, quality0=element_quality(mesh))
        dom._extension = dom._factor()
        return dom

    def _factor(self) -> tuple:
        """Factorised interior block of the stiffened Laplacian, and the boundary block."""
        m = self.mesh
        basis = Basis(m, ElementTriP2(), intorder=2)
        a, b, c = (m.p[:, m.t[i]] for i in range(3))
        area = 0.5 * np.abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        k = np.repeat(((area.max() / area) ** STIFFENING)[:, None], basis.X.shape[1], axis=1)
        K = _stiffened_laplace.assemble(basis, k=k).tocsr()
        bnd = np.unique(np.concatenate([self.surface, self.sphere, self.wall, self.axis]))
        inner = np.setdiff1d(np.arange(K.shape[0]), bnd)
        lu = spla.splu(K[inner][:, inner].tocsc())
        return inner, bnd, lu, K[inner][:, bnd].tocsr()

    @property
    def surface_xy(self) -> np.ndarray:
        """Free-surface nodes (2, 2N + 1), wall to sphere."""
        return self.mesh.doflocs[:, self.surface]

    @property
    def lower_name(self) -> str:
        """The lower solid's boundary name: ``"wall"``, ``"symmetry"`` or ``"sphere2"``."""
        return "sphere2" if self.radius2 is not None else self.plane

    def volume(self) -> float:
        return surface_volume(self.surface_xy, self.gap, self.radius2)

    def neck(self) -> tuple[float, float]:
        return neck(self.surface_xy)

    def moved(self, xs: np.ndarray, gap: float) -> Domain:
        """The domain with free surface ``xs`` (its ends on the lower solid and on the sphere
        at ``gap``), the other nodes placed by the rules of the module docstring."""
        x = self.reference.copy()
        f = self.fractions
        x[:, self.surface] = xs
        if self.radius2 is None:
            x[0, self.wall], x[1, self.wall] = f["wall"] * xs[0, 0], 0.0
        else:
            a2 = float(lower_angle(xs[:, :1], self.radius2)[0])
            x[:, self.wall] = on_lower(f["wall"] * a2, self.radius2)
        x[0, self.axis], x[1, self.axis] = 0.0, f["axis"] * gap
        phi = float(sphere_angle(xs[:, -1:], gap)[0])
        x[:, self.sphere] = on_sphere(f["sphere"] * phi, gap)
        inner, bnd, lu, Kib = self._extension
        d = x[:, bnd] - self.reference[:, bnd]
        for c in range(2):
            x[c, inner] = self.reference[c, inner] - lu.solve(Kib @ d[c])
        mesh = dataclasses.replace(self.mesh, doflocs=x)
        return dataclasses.replace(self, mesh=mesh, gap=gap)

    def quality(self) -> tuple[float, float]:
        """(min shape ratio to the reference mesh's, min curvature ratio) over the elements."""
        shape, curv = element_quality(self.mesh)
        return float(np.min(shape / self.quality0[0])), float(np.min(curv))
