"""Calibrated closures shipped with the package (level 0): arithmetic and a coefficient table.

``calibrated-viscous``
    Immersed sphere-wall and equal spheres, S/R in [1e-5, 100]: the exact Stokes correction
    written as ``lambda = q(t) (1 + s)/s`` (wall, s = S/R) or ``q(t) (1 + 2s)/(2s)`` (equal
    spheres, the force on each sphere at half the relative speed), with q a Chebyshev series
    in ``t = (2 ln s - ln s_min - ln s_max)/(ln s_max - ln s_min)``: q tends to 1 at both
    ends, so a few dozen terms reach the series (Brenner 1961; Maude 1961) to about 1e-9.
    Films on a wall, delta/R in [1e-3, 0.1], and bridges (H = sqrt(S^2 + V/(pi R*)),
    V/R_small^3 in [1e-4, 0.1], radius ratio 1-10): the Reynolds force times the refitted
    finite-liquid factor (:func:`wetcontact.reduced_models.forms.finite_liquid_form`), fitted to
    ``lubrication``; a bridge below the fitted S/H range (near contact) by its near-contact
    branch (:func:`bridge_force`), which tends to the Reynolds force; for films times a
    correction to ``stokes`` with the flat film top (:func:`film_correction`: lubrication
    is 0.4-73 % below it as the sphere leaves the film), the films' best reference.
    Bridges stay fitted to ``lubrication`` (labelled so in the table): ``stokes`` in a
    bridge adds the moving contact lines' dissipation, which depends on the slip length and
    which no closure here models.

The coefficients and held-out error tables are in ``data/calibrated_viscous.json``,
written by ``python -m wetcontact.generate calibrated-viscous``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from functools import cache
from importlib import resources
from typing import Any

import numpy as np

from wetcontact.errors import ValidityError
from wetcontact.models import ForceCurve, Model, closure_curve, register
from wetcontact.reduced_models.bounds import estimate_or_none
from wetcontact.scene import Scene

VISCOUS_FILE = "calibrated_viscous.json"

FILM_D = (1e-3, 0.1)
"""delta/R range of the film correction (the finite-liquid family's)."""
FILM_X = (0.01, 0.95)
"""S/delta range of the film correction."""


def film_coords(delta_over_r: np.ndarray, s_over_h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev coordinates of a film point: ``a`` from ln(delta/R), ``b`` from
    sqrt(1 - S/delta) (the wetted cap closes like that as the sphere leaves the film),
    each mapped from :data:`FILM_D` / :data:`FILM_X` to [-1, 1]."""
    lo, hi = math.log(FILM_D[0]), math.log(FILM_D[1])
    a = (2.0 * np.log(delta_over_r) - lo - hi) / (hi - lo)
    slo, shi = math.sqrt(1.0 - FILM_X[1]), math.sqrt(1.0 - FILM_X[0])
    b = (2.0 * np.sqrt(1.0 - s_over_h) - slo - shi) / (shi - slo)
    return a, b


def film_point(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(delta/R, S/delta) at the coordinates (a, b): the inverse of :func:`film_coords`."""
    lo, hi = math.log(FILM_D[0]), math.log(FILM_D[1])
    slo, shi = math.sqrt(1.0 - FILM_X[1]), math.sqrt(1.0 - FILM_X[0])
    return (np.exp(0.5 * (a * (hi - lo) + lo + hi)),
            1.0 - (0.5 * (b * (shi - slo) + slo + shi)) ** 2)


@cache
def viscous_table() -> dict[str, Any] | None:
    """The shipped table, or ``None`` before ``python -m wetcontact.generate
    calibrated-viscous``."""
    path = resources.files("wetcontact.reduced_models") / "data" / VISCOUS_FILE
    return json.loads(path.read_text()) if path.is_file() else None


def chebyshev_q(s: np.ndarray, log_range: tuple[float, float], coef: np.ndarray) -> np.ndarray:
    """``q(t) = sum_k c_k T_k(t)`` by Clenshaw's recurrence, t from ln s mapped to [-1, 1]."""
    lo, hi = log_range
    t = (2.0 * np.log(s) - lo - hi) / (hi - lo)
    b1 = np.zeros_like(t)
    b2 = np.zeros_like(t)
    for c in coef[:0:-1]:
        b1, b2 = 2.0 * t * b1 - b2 + c, b1
    return t * b1 - b2 + coef[0]


def immersed_lambda(s: np.ndarray, kind: str, table: dict[str, Any]) -> np.ndarray:
    """Calibrated Stokes correction (wall: F = 6 pi eta R v lambda; equal spheres:
    F = 6 pi eta R (v/2) lambda), from the Chebyshev table."""
    t = table["immersed"][kind]
    q = chebyshev_q(s, tuple(t["log_range"]), np.asarray(t["chebyshev"]))
    if kind == "sphere-wall":
        return q * (1.0 + s) / s
    return q * (1.0 + 2.0 * s) / (2.0 * s)


@register
class CalibratedViscous(Model):
    """Calibrated viscous closure: immersed (Chebyshev in log S/R), films and bridges
    (refitted finite-liquid factor)."""

    name = "calibrated-viscous"
    component = "viscous"
    validity = ("immersed sphere-wall or equal spheres, S/R in [1e-5, 100]; film on a wall, "
                "delta/R in [1e-3, 0.1], and bridges (wall, or spheres of radius ratio 1-10), "
                "V/R_small^3 in [1e-4, 0.1]: S/H in [0.01, 0.95] (films against stokes, "
                "flat top; bridges against lubrication; a bridge also below S/H = 0.01, by "
                "its near-contact branch tending to Reynolds); a film's gaps S >= delta give 0 "
                "(the sphere does not reach the liquid)")
    reference = ("calibrated here: Brenner (1961) series; stokes (flat top) for films; "
                 "lubrication for bridges")
    source = ("fitted here: Chebyshev tables of the exact series (Brenner 1961; Maude 1961) and "
              "the finite-liquid factor of Pitois, Moucheront & Chateau 2000 refitted to this "
              "package's lubrication and stokes solvers")
    cost = 3e-6  # a 48-term Chebyshev sum: about 3x a one-line closure (bench_calibrate)

    def check(self, scene: Scene) -> None:
        table = viscous_table()
        if table is None:
            raise ValidityError(self.name, "coefficient table not generated (python -m "
                                "wetcontact.generate calibrated-viscous)", "brenner")
        if scene.slip_length_sphere > 0 or scene.slip_length_wall > 0:
            raise ValidityError(self.name, "no slip calibrated", "vinogradova")
        if scene.amount == "immersed":
            if scene.kind == "sphere-sphere" and not scene.equal_spheres:
                raise ValidityError(self.name, "equal spheres only", "stokes")
            lo, hi = (math.exp(x) for x in table["immersed"][scene.kind]["log_range"])
            s = scene.gap_array / scene.radius
            if s.min() < lo * (1 - 1e-9) or s.max() > hi * (1 + 1e-9):
                raise ValidityError(self.name, f"S/R from {s.min():.3g} to {s.max():.3g} "
                                    f"outside the calibrated [{lo:.3g}, {hi:.3g}]", "brenner")
            return
        entry = _finite_entry(table, scene)
        coords = _finite_coords(scene)
        wet = _wetted(scene)
        if not wet.any():
            raise ValidityError(self.name, "every gap is >= the film thickness (the sphere "
                                "does not reach the liquid: no force)", "lubrication")
        for k, (lo, hi) in entry["domain"].items():
            v = coords[k][wet]
            if k == "s_over_h" and scene.amount == "bridge":
                lo = 0.0  # below the fitted range: the near-contact branch (bridge_force)
            if v.min() < lo * (1 - 1e-6) or v.max() > hi * (1 + 1e-6):
                raise ValidityError(self.name, f"{k} from {v.min():.4g} to {v.max():.4g} "
                                    f"outside the calibrated [{lo:.4g}, {hi:.4g}]",
                                    "lubrication")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        from wetcontact.reduced_models.forms import finite_liquid_form

        table = viscous_table()
        assert table is not None
        s = scene.gap_array
        eta, r, v = scene.viscosity, scene.radius, scene.velocity
        if scene.amount == "immersed":
            lam = immersed_lambda(s / r, scene.kind, table)
            speed = v if scene.kind == "sphere-wall" else 0.5 * v
            f = 6.0 * np.pi * eta * r * speed * lam
        else:
            n = s.size
            kappa = 1.0
            if scene.kind == "sphere-sphere":
                kappa = scene.reduced_radius**3 * (scene.radius**-3 + scene.radius2**-3)
            x = {"gap": s, "edge_gap": _edge_gap(scene), "kappa": np.full(n, kappa),
                 "r_star": np.full(n, scene.reduced_radius), "viscosity": np.full(n, eta),
                 "velocity": np.full(n, v)}
            entry = _finite_entry(table, scene)
            wet = _wetted(scene)
            f = np.zeros(n)
            k = np.asarray(entry["coefficients"])
            xw = {key: a[wet] for key, a in x.items()}
            f[wet] = (finite_liquid_form(k, xw) if scene.amount == "film"
                      else bridge_force(k, xw, entry["domain"]["s_over_h"][0]))
            if "stokes_correction" in entry:
                f[wet] *= film_correction(scene.film_thickness / r,
                                          s[wet] / scene.film_thickness,
                                          entry["stokes_correction"])
        from wetcontact.reduced_models.viscous import past_rupture_note

        return closure_curve(scene, self.name, viscous=f,
                             error_estimate=estimate_or_none(self.name, "viscous", scene),
                             outside=past_rupture_note(scene))


def bridge_force(k: np.ndarray, x: Mapping[str, np.ndarray], x_lo: float) -> np.ndarray:
    r"""Viscous force (N) of a pendular bridge: the refitted finite-liquid form on its
    fitted range, its near-contact branch below it.

    With x = S/H, H = sqrt(S^2 + V/(pi R*)) (Pitois et al. 2000) and the refitted factor
    :math:`\phi(x, d)` of :func:`~wetcontact.reduced_models.forms.finite_liquid_form`:

    .. math::
        F = F_R(S)\,\phi(x, d) \quad (x \ge x_0), \qquad
        F = F_R(S)\,(1 - x)^2 \left(1 + \rho \frac{x}{x_0}\right) \quad (x < x_0),

    :math:`F_R = 6 \pi \eta R^{*2} v/S` (Reynolds), :math:`x_0` the lower end of the fitted
    S/H range and :math:`\rho = \phi(x_0, d_0)/(1 - x_0)^2 - 1`, :math:`d_0` the factor's d
    at the gap where S/H = x_0 (H_0 = H sqrt((1 - x^2)/(1 - x_0^2))): Pitois'
    :math:`(1 - x)^2` times the refitted factor's departure from it at :math:`x_0`, taken
    linear in x (its leading order) below. The branch equals the form at :math:`x_0` (to
    rounding) and tends to the Reynolds force as S/H -> 0,
    :math:`F S/(6 \pi \eta R^{*2} v) \to 1`, as ``lubrication`` and ``reynolds-finite``
    do: the bridge is fully flooded relative to the gap and the surfaces' departure from
    the parabola is O(S/R*) there. (The refitted form's own value at x = 0,
    :math:`1 + c_0 d + c_4 d^2 + c_7 d^3`, is up to 2.6 % above that limit at V/R*^3 = 0.1:
    its terms in sqrt(x) were fitted on [x_0, 0.95] only.)

    Parameters
    ----------
    k
        The refitted coefficients (p, c0, ..., c8).
    x
        ``gap``, ``edge_gap`` (H), ``kappa``, ``r_star``, ``viscosity``, ``velocity``
        arrays, as :func:`~wetcontact.reduced_models.forms.finite_liquid_form` takes.
    x_lo
        :math:`x_0`, the fitted range's lower end of S/H.

    Returns
    -------
    numpy.ndarray
        The force (N), positive resisting approach.
    """
    from wetcontact.reduced_models.forms import finite_liquid_form

    gap, h = np.asarray(x["gap"], dtype=float), np.asarray(x["edge_gap"], dtype=float)
    xx = gap / h
    near = xx < x_lo
    out = np.asarray(finite_liquid_form(k, x), dtype=float)
    if not np.any(near):
        return out
    sub = {key: np.asarray(a)[near] for key, a in x.items()}
    xn = xx[near]
    h_lo = h[near] * np.sqrt((1.0 - xn**2) / (1.0 - x_lo**2))
    edge = {**sub, "gap": x_lo * h_lo, "edge_gap": h_lo, "velocity": np.ones_like(xn),
            "viscosity": np.ones_like(xn)}
    phi_lo = finite_liquid_form(k, edge) * (x_lo * h_lo) / (6.0 * np.pi * sub["r_star"] ** 2)
    rho = phi_lo / (1.0 - x_lo) ** 2 - 1.0
    rey = 6.0 * np.pi * sub["viscosity"] * sub["r_star"] ** 2 * sub["velocity"] / sub["gap"]
    out[near] = rey * (1.0 - xn) ** 2 * (1.0 + rho * xn / x_lo)
    return out


def film_correction(delta_over_r: float | np.ndarray, s_over_h: np.ndarray,
                    corr: dict[str, Any]) -> np.ndarray:
    """Factor taking the lubrication-fitted film closure to ``stokes`` (flat film top):
    ``exp(sum_ij C_ij T_i(a) T_j(b))``, (a, b) from :func:`film_coords`, C from
    :func:`wetcontact.calibrate.fit_film_stokes`."""
    a, b = film_coords(np.broadcast_to(delta_over_r, np.shape(s_over_h)), s_over_h)
    return np.exp(np.polynomial.chebyshev.chebval2d(a, b, np.asarray(corr["chebyshev_2d"])))


def _wetted(scene: Scene) -> np.ndarray:
    """Gaps at which the sphere reaches the liquid: all of a bridge's; a film's below its
    thickness (at S >= delta the flat film top has no wetted cap and the force is 0)."""
    s = scene.gap_array
    return s < scene.film_thickness if scene.amount == "film" else np.ones(s.shape, bool)


def _edge_gap(scene: Scene) -> np.ndarray:
    """Gap at the wetted edge: the film thickness, or Pitois' bridge edge gap."""
    s = scene.gap_array
    if scene.amount == "film":
        return np.full(s.shape, scene.film_thickness)
    return np.sqrt(s**2 + scene.bridge_volume / (np.pi * scene.reduced_radius))


def _finite_entry(table: dict[str, Any], scene: Scene) -> dict[str, Any]:
    return table["film"] if scene.amount == "film" else table["bridge"][scene.kind]


def _finite_coords(scene: Scene) -> dict[str, np.ndarray]:
    """Domain coordinates of a film or bridge scene (as in the calibration)."""
    s = scene.gap_array
    c = {"s_over_h": s / _edge_gap(scene)}
    if scene.amount == "film":
        c["delta_over_r"] = np.full(s.shape, scene.film_thickness / scene.radius)
    else:
        rs = scene.small_radius
        rl = scene.radius if scene.kind == "sphere-wall" else max(scene.radius, scene.radius2)
        c["v_star"] = np.full(s.shape, scene.bridge_volume / rs**3)
        c["radius_ratio"] = np.full(s.shape, rl / rs)
    return c
