"""Viscous closures (level 0) and the exact Stokes series that serve as analytic references.

Sign convention of the registered models: the axial force on the sphere, positive when it
pushes the surfaces apart, so the resistance to approach (``velocity > 0``) is positive.
For two spheres ``scene.velocity`` is the relative approach speed ``-dS/dt``; each sphere
moves at ``v/2`` toward the other.

All functions are vectorised over their array arguments and work in SI units.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import ForceCurve, Model, closure_curve, register
from wetcontact.reduced_models._checks import positive
from wetcontact.reduced_models.bounds import estimate_or_none
from wetcontact.scene import Scene

# ---- closed forms --------------------------------------------------------------------


def reynolds_force(eta: Any, r_star: Any, v: Any, gap: Any) -> np.ndarray:
    """Reynolds squeeze-film force, the closure every DEM code uses.

    ``F = 6 pi eta R*^2 v / S`` (Adams & Perchard 1985), with R* = R for a sphere and a
    wall and R* = R1 R2/(R1 + R2) for two spheres (relative approach speed v).

    Parameters
    ----------
    eta
        Viscosity (Pa s).
    r_star
        Reduced radius R* (m).
    v
        Approach speed (m/s), positive = approach.
    gap
        Surface gap S (m), > 0.

    Returns
    -------
    numpy.ndarray
        Force (N), positive = resisting approach. Valid for S << R* with the gap flooded.
    """
    gap = positive("gap", gap)
    return 6.0 * np.pi * np.asarray(eta) * np.asarray(r_star) ** 2 * np.asarray(v) / gap


def finite_liquid_factor(gap: Any, edge_gap: Any) -> np.ndarray:
    """Finite-liquid reduction of the Reynolds force, ``(1 - S/H)^2``, zero for S >= H.

    Pitois, Moucheront & Chateau (2000), J. Colloid Interface Sci. 231, 26: parabolic gap,
    ambient pressure at the wetted edge where the gap is H.

    Parameters
    ----------
    gap
        Surface gap S (m).
    edge_gap
        Gap H at the wetted edge (m): the film thickness, or :func:`bridge_edge_gap`.
    """
    gap = positive("gap", gap)
    h = positive("edge_gap", edge_gap)
    return np.where(gap < h, (1.0 - np.minimum(gap / h, 1.0)) ** 2, 0.0)


def bridge_edge_gap(gap: Any, volume: Any, r_eff: Any) -> np.ndarray:
    """Gap H at the edge of a bridge of volume V in a parabolic gap.

    ``H = sqrt(S^2 + V/(pi R_eff))`` from ``V = int_0^{r_w} 2 pi r h dr`` with
    ``h = S + r^2/(2 R_eff)`` (Pitois et al. 2000); R_eff = R (sphere-plane) or R*.
    """
    gap = positive("gap", gap)
    return np.sqrt(gap**2 + positive("volume", volume) / (np.pi * np.asarray(r_eff)))


def slip_factor(gap: Any, slip_length: Any, surfaces: int) -> np.ndarray:
    """Navier-slip reduction of the Reynolds force (Vinogradova 1995, Langmuir 11, 2213).

    Slip on both surfaces (same slip length b)::

        f = (S/3b) [(1 + S/6b) ln(1 + 6b/S) - 1]

    slip on one surface::

        f = (1/4) {1 + (3S/2b) [(1 + S/4b) ln(1 + 4b/S) - 1]}

    Both tend to 1 as b/S -> 0. Evaluated without cancellation via
    ``phi(x) = (1 + 1/x) ln(1 + x) - 1`` and its series for small x.

    Parameters
    ----------
    gap
        Surface gap S (m), > 0.
    slip_length
        b (m), > 0.
    surfaces
        1 or 2.
    """
    s = positive("gap", gap)
    b = positive("slip_length", slip_length)
    if surfaces == 2:
        x = 6.0 * b / s
        return 2.0 * _phi(x) / x
    if surfaces == 1:
        x = 4.0 * b / s
        return 0.25 * (1.0 + 6.0 * _phi(x) / x)
    raise InputError(f"slip_factor: surfaces = {surfaces!r}; allowed: 1 or 2")


def _phi(x: np.ndarray) -> np.ndarray:
    """``(1 + 1/x) ln(1 + x) - 1 = sum_{n>=1} (-1)^(n+1) x^n / (n (n+1))`` for x > 0."""
    x = np.asarray(x, dtype=float)
    small = x < 0.05
    out = np.empty_like(x)
    xs = x[small]
    series = np.zeros_like(xs)
    for n in range(14, 0, -1):  # Horner-like accumulation, |x| < 0.05: 14 terms >> 1e-16
        series = series + (-1.0) ** (n + 1) * xs**n / (n * (n + 1))
    out[small] = series
    xl = x[~small]
    out[~small] = (1.0 + 1.0 / xl) * np.log1p(xl) - 1.0
    return out


# ---- exact Stokes series --------------------------------------------------------------


def _sinh_minus_identity(y: np.ndarray) -> np.ndarray:
    """``sinh(y) - y`` without cancellation (series for |y| < 1, direct otherwise)."""
    y = np.atleast_1d(np.asarray(y, dtype=float))
    out = np.sinh(y) - y
    small = np.abs(y) < 1.0
    ys = y[small]
    y2 = ys * ys
    term = ys * y2 / 6.0
    acc = term.copy()
    for k in range(2, 12):  # y^(2k+1)/(2k+1)!; at |y| < 1, 11 terms reach 1e-20
        term = term * y2 / ((2 * k) * (2 * k + 1))
        acc += term
    out[small] = acc
    return out


def _series_setup(s: float) -> tuple[float, float, float, np.ndarray, np.ndarray]:
    """Bispherical parameter a = arccosh(1 + s), sinh a, sinh 2a, n and k = 2n + 1.

    a = log1p(s + sqrt(s (s + 2))) avoids cancellation at small s; sinh a = sqrt(s(s+2))
    exactly. Terms decay like x^2 exp(-x), x = (2n+1) a: summing to x >= 50 truncates
    below 1e-18 relative.
    """
    root = math.sqrt(s * (s + 2.0))
    a = math.log1p(s + root)
    sh = root
    sh2 = 2.0 * root * (1.0 + s)
    nmax = int(math.ceil((50.0 / a - 1.0) / 2.0)) + 5
    n = np.arange(1, nmax + 1, dtype=float)
    return a, sh, sh2, n, 2.0 * n + 1.0


def brenner_lambda(s_over_r: Any) -> np.ndarray:
    """Brenner's exact Stokes correction for a sphere moving normal to a plane wall.

    ``F = 6 pi eta R v lambda`` with (Brenner 1961, Chem. Eng. Sci. 16, 242, eq. 2.19)::

        lambda = (4/3) sinh(a) sum_{n>=1} n(n+1)/((2n-1)(2n+3)) *
                 [ (2 sinh((2n+1)a) + (2n+1) sinh(2a))
                   / (4 sinh^2((n+1/2)a) - (2n+1)^2 sinh^2(a)) - 1 ],
        a = arccosh(1 + S/R).

    The bracket minus one is evaluated as ``e^-x N / D`` (x = (2n+1)a) with no overflow
    and with the small-x denominator factored as
    ``(2 sinh(x/2) - k sinh a)(2 sinh(x/2) + k sinh a)``, whose first factor is written as
    ``2 g(x/2) - k g(a)``, g(y) = sinh y - y, free of cancellation. Accurate to ~1e-13
    relative for S/R in [1e-5, 1e3].

    Parameters
    ----------
    s_over_r
        S/R > 0, scalar or array.
    """
    s = positive("s_over_r", s_over_r)
    return np.vectorize(_brenner_scalar, otypes=[float])(s)


def _brenner_scalar(s: float) -> float:
    a, sh, sh2, n, k = _series_setup(float(s))
    x = k * a
    ex = np.exp(-x)
    num = -2.0 * np.expm1(-x) + k * sh2 + k * k * sh * sh  # (num - den) of the bracket
    small = x < 50.0
    den = np.empty_like(x)
    xs, ks = x[small], k[small]
    den[small] = (2.0 * _sinh_minus_identity(xs / 2.0) - ks * _sinh_minus_identity(np.array(a))
                  ) * (2.0 * np.sinh(xs / 2.0) + ks * sh)
    bracket = np.empty_like(x)
    bracket[small] = num[small] / den[small]
    xl = ~small
    # e^-x-scaled form where 4 sinh^2(x/2) = e^x (1 - e^-x)^2 would overflow.
    bracket[xl] = ex[xl] * num[xl] / (np.expm1(-x[xl]) ** 2 - k[xl] ** 2 * sh * sh * ex[xl])
    c = n * (n + 1.0) / ((2.0 * n - 1.0) * (2.0 * n + 3.0))
    return float(4.0 / 3.0 * sh * np.sum(c * bracket))


def two_sphere_lambda(h_over_r: Any) -> np.ndarray:
    """Exact Stokes correction for two equal spheres approaching each other.

    Each sphere moves at U toward the other (relative speed 2U); the force on each is
    ``F = 6 pi eta R U lambda_fs``. The same problem as a sphere approaching a shear-free
    plane (Brenner 1961; Maude 1961)::

        lambda_fs = (4/3) sinh(a) sum n(n+1)/((2n-1)(2n+3)) *
                    [ (4 cosh^2((n+1/2)a) + (2n+1)^2 sinh^2(a))
                      / (2 sinh((2n+1)a) - (2n+1) sinh(2a)) - 1 ],
        a = arccosh(1 + h/(2R)),  h = surface gap.

    The denominator is evaluated as ``2 g(x) - k g(2a)``, g(y) = sinh y - y (no
    cancellation), and in e^-x-scaled form at large x.

    Parameters
    ----------
    h_over_r
        Surface gap over sphere radius, > 0.
    """
    h = positive("h_over_r", h_over_r)
    return np.vectorize(_two_sphere_scalar, otypes=[float])(h)


def _two_sphere_scalar(h: float) -> float:
    a, sh, sh2, n, k = _series_setup(0.5 * float(h))
    x = k * a
    ex = np.exp(-x)
    rest = 2.0 + k * k * sh * sh + k * sh2  # numerator minus denominator, less 2 e^-x
    small = x < 50.0
    bracket = np.empty_like(x)
    xs, ks = x[small], k[small]
    den = 2.0 * _sinh_minus_identity(xs) - ks * _sinh_minus_identity(np.array(2.0 * a))
    bracket[small] = (2.0 * ex[small] + rest[small]) / den
    xl = ~small
    bracket[xl] = ex[xl] * (2.0 * ex[xl] + rest[xl]) / (
        -np.expm1(-2.0 * x[xl]) - k[xl] * sh2 * ex[xl]
    )
    c = n * (n + 1.0) / ((2.0 * n - 1.0) * (2.0 * n + 3.0))
    return float(4.0 / 3.0 * sh * np.sum(c * bracket))


def cox_brenner_lambda(s_over_r: Any) -> np.ndarray:
    """Inner (near-contact) expansion for a sphere approaching a wall.

    ``lambda = R/S + (1/5) ln(R/S) + 0.97128 + O((S/R) ln(S/R))``
    (Cox & Brenner 1967; constant from Cooley & O'Neill 1969).
    """
    s = positive("s_over_r", s_over_r)
    return 1.0 / s + 0.2 * np.log(1.0 / s) + 0.97128


def jeffrey_onishi_lambda(h_over_r: Any) -> np.ndarray:
    """Inner expansion for two equal spheres (Jeffrey & Onishi 1984).

    ``lambda_fs = R/(2h) + (9/20) ln(R/h) + 1.34558 + O((h/R) ln(h/R))``, same normalisation
    as :func:`two_sphere_lambda`.
    """
    h = positive("h_over_r", h_over_r)
    return 0.5 / h + 0.45 * np.log(1.0 / h) + 1.34558


def schaeffer_lambda(s_over_r: Any) -> np.ndarray:
    """Full-range fit of Brenner's series (Schaeffer, Norrelykke & Howard 2007).

    ``lambda = 1/(1 - 9/8 x + 1/2 x^3 - 57/100 x^4 + 1/5 x^5 + 7/200 x^11 - 1/25 x^12)``,
    ``x = R/(R + S)``; published maximum error about 0.3 %.
    """
    x = 1.0 / (1.0 + positive("s_over_r", s_over_r))
    return 1.0 / (1 - 9 / 8 * x + 0.5 * x**3 - 0.57 * x**4 + 0.2 * x**5 + 0.035 * x**11
                  - 0.04 * x**12)


# ---- registered models ---------------------------------------------------------------


def _scene_s(scene: Scene) -> np.ndarray:
    return scene.gap_array / scene.radius


def _brenner_reference(scene: Scene) -> np.ndarray:
    """Exact Stokes force (N) for an immersed sphere-wall or equal-sphere scene."""
    s = _scene_s(scene)
    eta, r, v = scene.viscosity, scene.radius, scene.velocity
    if scene.kind == "sphere-wall":
        return 6 * np.pi * eta * r * v * brenner_lambda(s)
    return 6 * np.pi * eta * r * (0.5 * v) * two_sphere_lambda(s)


def _require_immersed(model: str, scene: Scene, equal: bool = True) -> None:
    if scene.amount != "immersed":
        raise ValidityError(model, f"an exact immersed-sphere result; amount is "
                            f"'{scene.amount}'", "reynolds-finite" if scene.amount != "film"
                            else "thinfilm")
    if equal and scene.kind == "sphere-sphere" and not scene.equal_spheres:
        raise ValidityError(model, "two-sphere series is for equal radii; radius2 = "
                            f"{scene.radius2:g} m != radius = {scene.radius:g} m", "stokes")


#: S/R* beyond which the flooded-gap closures are outside their stated validity (Reynolds is
#: 12.7 % below Brenner's exact force at S/R = 0.1)
THIN_GAP_LIMIT = 0.1


def flooded_gap_note(scene: Scene) -> str:
    """Why a scene lies outside the stated validity of a flooded thin-gap closure
    (``reynolds``, ``vinogradova``): finite liquid (a film or a bridge), or a gap beyond
    :data:`THIN_GAP_LIMIT` R*. Empty inside it."""
    notes = []
    if scene.amount != "immersed":
        notes.append(f"flooded gap assumed, but the liquid is a {scene.amount}")
    s = float(np.max(scene.gap_array)) / scene.reduced_radius
    if s > THIN_GAP_LIMIT:
        notes.append(f"S/R* up to {s:.3g} > {THIN_GAP_LIMIT:g}, the thin-gap limit: 12.7 % "
                     "low at 0.1 against Brenner")
    return "; ".join(notes)


@register
class Reynolds(Model):
    """``F = 6 pi eta R*^2 v / S``: the DEM closure, flooded gap, no slip, no inertia."""

    name = "reynolds"
    component = "viscous"
    validity = "S/R* << 1 (12.7 % low at S/R = 0.1 against Brenner); flooded gap"
    reference = "Adams & Perchard (1985)"
    source = "Adams & Perchard 1985"

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        f = reynolds_force(scene.viscosity, scene.reduced_radius, scene.velocity,
                           scene.gap_array)
        est = None
        if scene.amount == "immersed" and (scene.kind == "sphere-wall" or scene.equal_spheres):
            est = np.abs(f / _brenner_reference(scene) - 1.0) if scene.velocity else None
        return closure_curve(scene, self.name, viscous=f, error_estimate=est,
                             outside=flooded_gap_note(scene))


def finite_liquid_note(scene: Scene) -> str:
    """Why a film or bridge scene lies outside the stated validity of ``reynolds-finite``:
    a gap beyond :data:`THIN_GAP_LIMIT` R* (not a thin parabolic gap); a wetted radius
    ``r_w = sqrt(2 R* (H - S))`` beyond ``R sin 60 deg`` (R the smaller radius), where the
    sphere is steeper than 60 deg and the parabolic gap fails (``lubrication`` refuses
    such a liquid amount); or for a bridge gaps past its rupture distance
    (:func:`past_rupture_note`: no bridge there, but ``H = sqrt(S^2 + V/(pi R*))`` stays
    above S, so the factor never reaches 0). Empty inside it."""
    notes = []
    gaps = scene.gap_array
    s = float(np.max(gaps)) / scene.reduced_radius
    if s > THIN_GAP_LIMIT:
        notes.append(f"S/R* up to {s:.3g} > {THIN_GAP_LIMIT:g}, the thin-gap limit")
    h = (np.full_like(gaps, scene.film_thickness) if scene.amount == "film"
         else bridge_edge_gap(gaps, scene.bridge_volume, scene.reduced_radius))
    r_w = float(np.max(np.sqrt(2 * scene.reduced_radius * np.maximum(h - gaps, 0.0))))
    if r_w > (r_max := math.sin(math.radians(60.0)) * scene.small_radius):
        notes.append(f"wetted radius up to {r_w:.3g} m > R sin 60 deg = {r_max:.3g} m: the "
                     "sphere is steeper than 60 deg at the liquid's edge, where the parabolic "
                     "gap fails")
    if note := past_rupture_note(scene):
        notes.append(note)
    return "; ".join(notes)


def bridge_rupture_distance(scene: Scene) -> tuple[float, str]:
    """A bridge's rupture distance (m) and where it comes from: ``calibrated-capillary``'s
    (within 5e-4 of the FE bridge's over its box: V/R_small^3 1e-4 to 0.1, 0-70 deg,
    radius ratio 1-10), else Lian's ``S_c = (1 + theta/2) V^(1/3)`` (Lian et al. 1993,
    theta the mean contact angle; on a wall it lies 4-34 % beyond the FE fold at 20 deg)."""
    from wetcontact.models import _accepts, get_model
    from wetcontact.reduced_models.capillary import mean_contact_angle
    from wetcontact.reduced_models.rupture import lian_rupture_distance

    cal = get_model("calibrated-capillary")
    if _accepts(cal, scene):
        return cal.rupture_distance(scene), "calibrated-capillary"  # type: ignore[attr-defined]
    return float(lian_rupture_distance(scene.bridge_volume, mean_contact_angle(
        scene.contact_angle_sphere, scene.contact_angle_wall))), "Lian 1993"


def past_rupture_note(scene: Scene) -> str:
    """For a bridge, how many of the scene's gaps are at or past its rupture distance
    (:func:`bridge_rupture_distance`), where there is no bridge and so no viscous force;
    empty otherwise. For the viscous models of a bridge (thin-gap and calibrated), which
    take the bridge's liquid as a disk between the surfaces at every gap."""
    if scene.amount != "bridge":
        return ""
    gaps = scene.gap_array
    sc, source = bridge_rupture_distance(scene)
    if not (n := int(np.sum(gaps >= sc))):
        return ""
    return (f"{n} of {gaps.size} gaps at or past the bridge's rupture distance "
            f"({source}: {sc:.3g} m), where there is no bridge")


@register
class ReynoldsFinite(Model):
    """Reynolds times the finite-liquid factor ``(1 - S/H)^2`` (Pitois et al. 2000)."""

    name = "reynolds-finite"
    component = "viscous"
    validity = "film or bridge; S << R*, parabolic gap, ambient pressure at the wetted edge"
    reference = "Pitois, Moucheront & Chateau (2000)"
    source = "Pitois, Moucheront & Chateau 2000, J. Colloid Interface Sci. 231, 26"

    def check(self, scene: Scene) -> None:
        if scene.amount == "immersed":
            raise ValidityError(self.name, "needs a film thickness or a bridge volume; the "
                                "scene is immersed", "brenner")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        s = scene.gap_array
        if scene.amount == "film":
            h = np.full_like(s, scene.film_thickness)
        else:
            h = bridge_edge_gap(s, scene.bridge_volume, scene.reduced_radius)
        f = reynolds_force(scene.viscosity, scene.reduced_radius, scene.velocity, s)
        fac = finite_liquid_factor(s, h)
        return closure_curve(scene, self.name, viscous=f * fac, edge_gap=h,
                             error_estimate=estimate_or_none(self.name, "viscous", scene),
                             wetted_radius=np.sqrt(2 * scene.reduced_radius
                                                   * np.maximum(h - s, 0.0)),
                             outside=finite_liquid_note(scene))


@register
class Brenner(Model):
    """Exact Stokes series: Brenner (1961) sphere-wall, or the equal two-sphere series."""

    name = "brenner"
    component = "viscous"
    validity = "immersed; sphere-wall or equal spheres; any S/R (exact Stokes flow, Re << 1)"
    reference = "Brenner (1961); Maude (1961)"
    source = "Brenner 1961, Chem. Eng. Sci. 16, 242; equal spheres: Maude 1961"
    reference_rank = {"viscous": 40}  # exact series: the best viscous reference
    cost = 1e-4  # up to ~2000 series terms per gap at S/R = 1e-4

    def check(self, scene: Scene) -> None:
        _require_immersed(self.name, scene)

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        # exact Stokes solution: the estimate is the summation accuracy (1e-15 measured
        # against a 40-digit sum, stated with margin)
        f = _brenner_reference(scene)
        return closure_curve(scene, self.name, viscous=f, error_estimate=np.full(f.shape, 1e-12))


@register
class CoxBrenner(Model):
    """Inner expansion: Cox & Brenner (1967) for a wall, Jeffrey & Onishi (1984) for spheres."""

    name = "cox-brenner"
    component = "viscous"
    validity = ("immersed; S/R <= 1 (error O((S/R) ln(R/S)), measured against the exact "
                "series: 4.9e-7 (wall) and 1.1e-6 (two spheres) at S/R = 1e-3, 7.3 % and "
                "9.5 % at S/R = 1; the two-sphere form crosses zero at S/R = 20.97, the wall "
                "form at 133)")
    reference = "Cox & Brenner (1967); Cooley & O'Neill (1969); Jeffrey & Onishi (1984)"
    source = ("Cox & Brenner 1967 (constant: Cooley & O'Neill 1969); equal spheres: Jeffrey & "
              "Onishi 1984")
    max_s_over_r = 1.0

    def check(self, scene: Scene) -> None:
        _require_immersed(self.name, scene)
        s = float(_scene_s(scene).max())
        if s > self.max_s_over_r:
            raise ValidityError(self.name, f"S/R = {s:.4g} > {self.max_s_over_r:g}: the inner "
                                "expansion is more than 7.3 % (wall) or 9.5 % (two spheres) "
                                "off there, and negative for two spheres from S/R = 20.97",
                                "brenner")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        s = _scene_s(scene)
        eta, r, v = scene.viscosity, scene.radius, scene.velocity
        if scene.kind == "sphere-wall":
            lam, speed = cox_brenner_lambda(s), v
        else:
            lam, speed = jeffrey_onishi_lambda(s), 0.5 * v
        # the measured held-out bound (reduced_models/data/bounds.json), not the
        # a-priori O((S/R) ln(R/S)) term, which vanishes at S/R = 1
        return closure_curve(scene, self.name, viscous=6 * np.pi * eta * r * speed * lam,
                             error_estimate=estimate_or_none(self.name, "viscous", scene))


@register
class Schaeffer(Model):
    """Full-range fit of the sphere-wall correction (Schaeffer et al. 2007)."""

    name = "schaeffer"
    component = "viscous"
    validity = ("immersed sphere-wall; any S/R; published max error about 0.3 %, measured "
                "3.33e-3 at S/R 0.012-0.04")
    reference = "Schaeffer, Norrelykke & Howard (2007), Langmuir 23, 3654"
    source = "Schaeffer, Norrelykke & Howard 2007, Langmuir 23, 3654"

    def check(self, scene: Scene) -> None:
        _require_immersed(self.name, scene)
        if scene.kind != "sphere-wall":
            raise ValidityError(self.name, "fitted for a sphere and a wall", "brenner")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        lam = schaeffer_lambda(_scene_s(scene))
        f = 6 * np.pi * scene.viscosity * scene.radius * scene.velocity * lam
        return closure_curve(scene, self.name, viscous=f,
                             error_estimate=estimate_or_none(self.name, "viscous", scene))


@register
class Vinogradova(Model):
    """Reynolds force times the Navier-slip factor of Vinogradova (1995)."""

    name = "vinogradova"
    component = "viscous"
    validity = ("S << R*, flooded gap; slip on one surface, or the same slip length on "
                "both")
    reference = "Vinogradova (1995), Langmuir 11, 2213"
    source = "Vinogradova 1995, Langmuir 11, 2213"

    def check(self, scene: Scene) -> None:
        b1, b2 = scene.slip_length_sphere, scene.slip_length_wall
        if b1 == 0 and b2 == 0:
            raise ValidityError(self.name, "no slip length given (both zero)", "reynolds"
                                if scene.amount == "immersed" else "reynolds-finite")
        if b1 > 0 and b2 > 0 and not math.isclose(b1, b2, rel_tol=1e-12):
            raise ValidityError(self.name, f"unequal slip lengths {b1:g} m and {b2:g} m have "
                                "no closed form", "lubrication")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        b1, b2 = scene.slip_length_sphere, scene.slip_length_wall
        s = scene.gap_array
        fac = slip_factor(s, max(b1, b2), 2 if (b1 > 0 and b2 > 0) else 1)
        f = reynolds_force(scene.viscosity, scene.reduced_radius, scene.velocity, s)
        return closure_curve(scene, self.name, viscous=f * fac, outside=flooded_gap_note(scene))
