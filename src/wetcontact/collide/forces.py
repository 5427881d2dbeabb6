"""Force tables of one collision: each force model evaluated once along the gap.

The viscous force of every model in the toolkit is linear in the approach speed, so one
curve at unit speed, ``f1(S) = F_v(S, v = 1 m/s)``, gives ``F_v = v f1(S)`` at every step.
The capillary force depends on the gap and the bridge's volume and contact angles, so one
curve per (volume, angles) serves a whole trajectory.

Each curve is tabulated on a uniform grid and interpolated by a not-a-knot cubic spline:
viscous curves as ``S f1(S)`` against ``u = ln S`` (smooth and bounded where
``f1 ~ 1/S``); capillary curves as ``F_c`` against ``q = sqrt(1 - S/S_c)``, in which the
square-root shape of the force at the bridge's fold (``dF/dS`` unbounded at ``S_c``)
is smooth. The grid is doubled until the spline's largest error at the
midpoints between nodes, measured against the model itself, is below ``rtol`` of the
table's largest magnitude (default 1e-8): the interpolation error of the force, which is
reported as ``interpolation_error``. A cubic spline's error is O(h^4), so doubling the
grid lowers it about 16-fold; a restitution error of 1e-6 needs a force error well below
1e-6 relative, which 1e-8 gives with a margin.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import CubicSpline

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import MODELS, Model, get_model
from wetcontact.scene import Scene

#: relative interpolation error the tables are refined to (of their largest magnitude)
TABLE_RTOL = 1e-8
#: nodes of the first grid and the most any table is refined to
TABLE_START, TABLE_MAX = 65, 4097
#: wall time (s) one table may spend in a model, which caps the nodes of costly solvers
TABLE_BUDGET_S = 120.0

#: default force models, most trusted first; the first that accepts the scene is used
DEFAULT_VISCOUS = ("calibrated-viscous", "brenner", "lubrication", "reynolds-finite",
                   "reynolds")
DEFAULT_CAPILLARY = ("calibrated-capillary", "meniscus")


@dataclass(frozen=True)
class GapTable:
    """A force curve tabulated along ln S and interpolated by a cubic spline.

    Attributes
    ----------
    model
        The model that produced the nodes.
    lo, hi
        Tabulated gap range (m); outside it the caller decides (zero beyond ``hi``).
    scaled
        True: the spline holds ``S F(S)`` (viscous tables), else ``F(S)``.
    interpolation_error
        Largest relative error at the midpoints between nodes (of the largest magnitude).
    nodes
        Number of nodes.
    """

    model: str
    lo: float
    hi: float
    scaled: bool
    spline: CubicSpline
    interpolation_error: float
    nodes: int

    def __call__(self, gap: float) -> float:
        """Force (N) at ``gap`` in [lo, hi] (clamped into it)."""
        s = min(max(gap, self.lo), self.hi)
        if self.scaled:
            return float(self.spline(math.log(s))) / s
        return float(self.spline(math.sqrt(max(1.0 - s / self.hi, 0.0))))

    @staticmethod
    def coordinate(gaps: np.ndarray, hi: float, scaled: bool) -> np.ndarray:
        """The spline's abscissa of ``gaps``: ln S (viscous) or sqrt(1 - S/hi)."""
        return np.log(gaps) if scaled else np.sqrt(np.maximum(1.0 - gaps / hi, 0.0))

    @staticmethod
    def gaps_of(coord: np.ndarray, hi: float, scaled: bool) -> np.ndarray:
        """Gaps (m) at the abscissae ``coord``."""
        return np.exp(coord) if scaled else hi * (1.0 - coord * coord)


@dataclass(frozen=True)
class DirectForce:
    """A closed-form force evaluated directly along the path (no table): a DEM code's law.

    Attributes
    ----------
    model
        Its name (e.g. ``"mercurydpm:willett"``).
    fn
        Force (N; viscous: per unit speed, N s/m) at the gap (m).
    """

    model: str
    fn: Callable[[float], float]
    hi: float = math.inf
    interpolation_error: float = 0.0
    nodes: int = 0

    def __call__(self, gap: float) -> float:
        """Force at ``gap`` (m)."""
        return self.fn(gap)


def _evaluate(model: Model, scene: Scene, gaps: np.ndarray, component: str) -> np.ndarray:
    curve = model.force(scene, gaps)
    f = curve.force_viscous if component == "viscous" else curve.force_capillary
    if f is None:
        raise ValidityError(model.name, f"gives no {component} force for this scene")
    f = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(f)):
        bad = gaps[~np.isfinite(f)]
        raise ValidityError(model.name, f"{component} force not finite at {bad.size} of "
                            f"{gaps.size} gaps (first {bad[0]:.4g} m) along the collision")
    return f


def tabulate(model: Model, scene: Scene, lo: float, hi: float, component: str,
             rtol: float = TABLE_RTOL) -> GapTable:
    """Tabulate ``model``'s force on ``scene`` between the gaps ``lo`` and ``hi``.

    Parameters
    ----------
    model, scene
        The force model and the scene it is evaluated on (viscous: at the scene's speed,
        which the caller sets to 1 m/s).
    lo, hi
        Gap range (m), 0 < lo < hi.
    component
        ``"viscous"`` (spline of S F) or ``"capillary"`` (spline of F).
    rtol
        Target interpolation error relative to the table's largest magnitude.

    Returns
    -------
    GapTable
        Refined until the midpoint error is below ``rtol`` or the node cap (``TABLE_MAX``,
        or fewer for a costly model: ``TABLE_BUDGET_S`` over its cost per gap).
    """
    scaled = component == "viscous"
    cap = int(min(TABLE_MAX, max(TABLE_START, TABLE_BUDGET_S / max(model.cost, 1e-9))))
    n = TABLE_START
    ends = GapTable.coordinate(np.array([lo, hi]), hi, scaled)
    if not scaled:  # the fold's side first, kept 1e-12 S_c short of it
        ends = np.array([1e-6, ends[0]])
    u = np.linspace(ends[0], ends[1], n)
    g = GapTable.gaps_of(u, hi, scaled)
    vals = _evaluate(model, scene, g, component) * (g if scaled else 1.0)
    while True:
        spline = CubicSpline(u, vals)
        um = 0.5 * (u[1:] + u[:-1])
        gm = GapTable.gaps_of(um, hi, scaled)
        mid = _evaluate(model, scene, gm, component) * (gm if scaled else 1.0)
        scale = max(float(np.max(np.abs(vals))), float(np.max(np.abs(mid))), 1e-300)
        err = float(np.max(np.abs(spline(um) - mid))) / scale
        # merge the midpoints in: the next grid is the doubled one, nothing evaluated twice
        uu = np.empty(2 * n - 1)
        vv = np.empty(2 * n - 1)
        uu[0::2], uu[1::2] = u, um
        vv[0::2], vv[1::2] = vals, mid
        if err <= rtol or 2 * n - 1 > cap:
            # err is that of the coarser spline: an upper bound for the finer one returned
            return GapTable(model.name, lo, hi, scaled, CubicSpline(uu, vv), err, 2 * n - 1)
        u, vals, n = uu, vv, 2 * n - 1


def _accepts(model: Model, scene: Scene) -> bool:
    return model.applicable(scene) is None


def _registered(name: str) -> bool:
    try:
        get_model(name)
    except InputError:
        return False
    return True


def pick_model(name: str | None, scene: Scene, component: str) -> Model | None:
    """The model for ``component`` on ``scene``: the named one (``"none"``: no force), or
    the first of the defaults that accepts the scene.

    Raises
    ------
    InputError
        An unknown name, a model of the other component, or a named model that refuses
        the scene (its message names the model that applies).
    """
    if name == "none":
        return None
    if name is not None:
        model = get_model(name)  # an unknown name: the registry's one-line error
        if model.component not in (component, "both"):
            raise InputError(f"--{component} {name}: a {model.component} model; allowed: a "
                             f"{component} model (wetcontact models) or none")
        model.check(scene)
        return model
    defaults = DEFAULT_VISCOUS if component == "viscous" else DEFAULT_CAPILLARY
    for cand in defaults:  # get_model fills the registry on first use
        if cand in MODELS or _registered(cand):
            if _accepts(MODELS[cand], scene):
                return MODELS[cand]
    raise ValidityError(defaults[0], f"no default {component} model accepts the scene; "
                        "name one with --" + component)


def table_for(name: str | None, scene: Scene, lo: float, hi: float, component: str
              ) -> GapTable | None:
    """The force table of ``component`` on ``scene`` between the gaps ``lo`` and ``hi``.

    A named model is used or refused (its refusal names the model that applies); without a
    name, the defaults are tried in order and the first that accepts the scene at every
    gap of the table is used (``calibrated-viscous`` refuses films whose roughness gap lies
    below its calibrated S/H, ``lubrication`` takes over there). ``"none"``: None.
    """
    key = (name, scene.canonical_json(), lo, hi, component)
    if key in _TABLES:
        return _TABLES[key]
    table = _table_for(name, scene, lo, hi, component)
    if len(_TABLES) >= TABLE_CACHE:
        _TABLES.pop(next(iter(_TABLES)))
    _TABLES[key] = table
    return table


#: force tables kept for reuse (a collision study varies the speed or the mass at one
#: geometry: the tables, at unit speed, are the same)
TABLE_CACHE = 256
_TABLES: dict[tuple, GapTable | None] = {}


def _table_for(name: str | None, scene: Scene, lo: float, hi: float, component: str
               ) -> GapTable | None:
    model = pick_model(name, scene, component)
    if model is None:
        return None
    if name is not None:
        return tabulate(model, scene, lo, hi, component)
    defaults = DEFAULT_VISCOUS if component == "viscous" else DEFAULT_CAPILLARY
    first: InputError | None = None
    for cand in defaults[defaults.index(model.name):]:
        if cand not in MODELS or not _accepts(MODELS[cand], scene):
            continue
        try:
            return tabulate(MODELS[cand], scene, lo, hi, component)
        except InputError as exc:  # refused at some gap of the table: the next default
            first = first or exc
    raise first or ValidityError(defaults[0], f"no default {component} model accepts the "
                                 "scene; name one with --" + component)


def bridge_scene(scene: Scene, volume: float, angles: tuple[float, float]) -> Scene:
    """The scene as a pendular bridge of ``volume`` (m^3) with contact angles ``angles``
    (rad; first sphere, wall or second sphere)."""
    return replace(scene, amount="bridge", bridge_volume=volume, film_thickness=None,
                   contact_angle_sphere=angles[0], contact_angle_wall=angles[1])


def gathered_volume(scene: Scene) -> float:
    """Film volume the sphere gathers into its bridge (m^3): the film inside the wetted
    cylinder of radius ``r_w = sqrt(2 R delta - delta^2)`` less the sphere's cap below the
    film surface, ``V = pi delta^2 (R - 2 delta / 3)`` (R = R*, delta the film thickness).
    For delta << R it is ``pi R delta^2``, the volume whose Pitois edge gap
    ``sqrt(V/(pi R))`` is delta."""
    d = float(scene.film_thickness)
    return math.pi * d * d * (scene.reduced_radius - 2.0 * d / 3.0)


def rupture_distance(model: Model, scene: Scene) -> float:
    """Static rupture distance (m) of the bridge ``scene`` as ``model`` gives it: the
    model's ``rupture_distance`` extra (or method); Lian et al. 1993's
    ``(1 + theta/2) V^(1/3)`` (theta the mean angle) for a model that gives none."""
    fn: Callable[[Scene], float] | None = getattr(model, "rupture_distance", None)
    if fn is not None:
        return float(fn(scene))
    curve = model.force(scene, [1e-3 * scene.small_radius])
    if "rupture_distance" in curve.extras:
        return float(curve.extras["rupture_distance"][0])
    theta = 0.5 * (scene.contact_angle_sphere + scene.contact_angle_wall)
    return (1.0 + 0.5 * theta) * float(scene.bridge_volume) ** (1.0 / 3.0)
