"""The force sets of DEM codes, as each code applies them, for the restitution error tables.

Each set maps a collision case to the viscous and capillary laws the code would apply, when
it applies them (approach, rebound), its rupture distance and its cut-offs. The DEM gap
``s = x - x_r`` is zero at solid contact (the codes' contact); the laws are functions of
it. ``collide(case, force_set=NAME)`` integrates the impact with a set instead of the
toolkit's models, so the same integrator measures every set against the reference.

Sets (formulas as read in each code's source; ``R*`` the reduced radius, R* = R on a wall):

- ``mercurydpm``: MercuryDPM ``LiquidMigrationWilletInteraction``: viscous
  ``6 pi eta R*^2 v / s`` only after the first contact and zero for ``s < R*/100``;
  capillary ``-2 pi R' sigma cos(theta) / (1 + (1.05 + 2.5 s_c) s_c)``, ``R' = 2 R*``,
  ``s_c = s sqrt(R'/V)`` (Willett's simple form); rupture ``(1 + theta/2) V^(1/3)``.
- ``reynolds-willett-lian``: the textbook set: Reynolds ``6 pi eta R*^2 v / x`` on approach
  and rebound with a constant value below the roughness gap, Willett's full fit after
  contact (R = 2 R*), Lian's rupture ``(1 + theta/2) V^(1/3)``.
- ``yade-lubrication``: Yade ``Law2_ScGeom_ImplicitLubricationPhys``:
  ``F = (3/2) pi eta a^2 v / u`` with ``a = (R1 + R2)/2`` (a wall: a = R, the code's
  sphere-sphere form), asperity contact at ``u = 2 eps a``, eps = 1e-3; no capillary force.
- ``yade-viscelcap``: Yade's ViscElCap law with Willett's bridge (:func:`yade_viscelcap`).
- ``liggghts-easo``: LIGGGHTS' hertz + easo/capillary/viscous (:func:`liggghts_easo`).

The last two reproduce the codes' own restitution within 6e-5 (``benchmarks/dem``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from wetcontact.collide.case import CollisionCase
from wetcontact.collide.forces import DirectForce, gathered_volume
from wetcontact.errors import InputError
from wetcontact.reduced_models.capillary import willett_force


@dataclass(frozen=True)
class SetForces:
    """What a force set applies in one collision (engine gaps x, contact at ``x_r``).

    Attributes
    ----------
    tables
        ``viscous_approach``, ``viscous_rebound``, ``capillary_approach``,
        ``capillary_rebound``: each a :class:`DirectForce` or absent.
    reach
        Gap (m) below which the approach forces act.
    rupture
        Gap (m) where the bridge (and the rebound forces) end.
    volume
        Bridge volume (m^3), or None.
    roughness
        Gap of solid contact (m) the set uses (the case's unless the code fixes its own).
    contact
        The code's own solid contact law, ``F(overlap d, dd/dt)`` (N), or None for the
        case's ``[contact]`` model.
    cutoff
        The viscous force inside the solid contact, as the case's ``contact.cutoff``, where
        the code fixes it.
    """

    tables: dict[str, DirectForce] = field(default_factory=dict)
    reach: float = math.inf
    rupture: float = math.inf
    volume: float | None = None
    roughness: float | None = None
    contact: Callable[[float, float], float] | None = None
    cutoff: str | None = None


def _volume(case: CollisionCase) -> float:
    sc = case.scene
    if sc.amount == "bridge":
        return float(sc.bridge_volume)
    if sc.amount == "film":
        return gathered_volume(sc)
    raise InputError(f"{sc.origin}: a DEM code's capillary set needs a film or a bridge; the "
                     "scene is immersed")


def _mean_angle(case: CollisionCase, receding: bool = True) -> float:
    sc = case.scene
    ang = (case.receding_angle if receding else case.advancing_angle) or (
        sc.contact_angle_sphere, sc.contact_angle_wall)
    return 0.5 * (ang[0] + ang[1])


def mercurydpm(case: CollisionCase, x_r: float) -> SetForces:
    """MercuryDPM's Willett liquid bridge (see the module docstring)."""
    sc = case.scene
    vol, th, rs = _volume(case), _mean_angle(case), sc.reduced_radius
    eta, sig = sc.viscosity, sc.surface_tension
    r_prime = 2.0 * rs
    rupture = (1.0 + 0.5 * th) * vol ** (1.0 / 3.0)

    def visc(x: float) -> float:
        s = x - x_r
        return 0.0 if s < rs / 100.0 else 6.0 * math.pi * eta * rs * rs / s

    def cap(x: float) -> float:
        s_c = max(x - x_r, 0.0) * math.sqrt(r_prime / vol)
        return -2.0 * math.pi * r_prime * sig * math.cos(th) / (1.0 + (1.05 + 2.5 * s_c) * s_c)

    return SetForces({"viscous_rebound": DirectForce("mercurydpm", visc),
                      "capillary_rebound": DirectForce("mercurydpm", cap)},
                     reach=x_r, rupture=x_r + rupture, volume=vol)


def reynolds_willett_lian(case: CollisionCase, x_r: float) -> SetForces:
    """Reynolds with a constant cut-off, Willett's fit and Lian's rupture."""
    sc = case.scene
    vol, th, rs = _volume(case), _mean_angle(case), sc.reduced_radius
    eta, sig = sc.viscosity, sc.surface_tension
    rupture = (1.0 + 0.5 * th) * vol ** (1.0 / 3.0)
    reach = (float(sc.film_thickness) if sc.amount == "film" else
             (1.0 + 0.5 * _mean_angle(case, False)) * vol ** (1.0 / 3.0))

    def visc(x: float) -> float:
        return 6.0 * math.pi * eta * rs * rs / max(x, x_r)

    def cap(x: float) -> float:
        return -float(willett_force(max(x, 0.0), vol, sc.willett_radius, sig, th))

    v = DirectForce("reynolds-willett-lian", visc)
    return SetForces({"viscous_approach": v, "viscous_rebound": v,
                      "capillary_rebound": DirectForce("reynolds-willett-lian", cap)},
                     reach=reach, rupture=rupture, volume=vol)


YADE_EPS = 1e-3


def yade_lubrication(case: CollisionCase, x_r: float) -> SetForces:
    """Yade's implicit lubrication law, no capillary force."""
    sc = case.scene
    a = sc.radius if sc.kind == "sphere-wall" else 0.5 * (sc.radius + float(sc.radius2))
    eta, rough = sc.viscosity, 2.0 * YADE_EPS * a

    def visc(x: float) -> float:
        return 1.5 * math.pi * eta * a * a / max(x, rough)

    v = DirectForce("yade-lubrication", visc)
    return SetForces({"viscous_approach": v, "viscous_rebound": v}, reach=math.inf,
                     rupture=case.impact.start_gap if not math.isnan(case.impact.start_gap)
                     else sc.radius, roughness=rough)


def _masses(case: CollisionCase) -> tuple[float, float]:
    """(m1, m*) of the pair (a wall: m* = m1)."""
    sc = case.scene
    m1 = case.solid.density * 4.0 / 3.0 * math.pi * sc.radius ** 3
    if sc.kind == "sphere-wall":
        return m1, m1
    m2 = case.solid2.density * 4.0 / 3.0 * math.pi * float(sc.radius2) ** 3
    return m1, m1 * m2 / (m1 + m2)


def yade_viscelcap(case: CollisionCase, x_r: float, tc: float = 2e-5,
                   dcap: float = 0.0) -> SetForces:
    """Yade 2023.02a ``ViscElCapMat`` with ``Law2_ScGeom_ViscElCapPhys_Basic``
    (``pkg/dem/ViscoelasticPM.cpp``, ``ViscoelasticCapillarPM.cpp``), Willett_numeric:

    - contact: ``F = max(0, kn d + cn dd/dt)``, ``kn = (pi^2 + ln^2 e) m*/tc^2``,
      ``cn = -2 ln(e) m*/tc`` (e the case's e_dry, ``tc`` the contact time);
    - after the first contact, while the surfaces are apart: Willett's fit with
      ``R = 2 R1 R2/(R1 + R2)`` and the bridge damping ``dcap v``; nothing during contact
      or on approach;
    - rupture at Willett's ``(1 + theta/2)(V*^(1/3) + 0.1 V*^(2/3)) R``, V* = V/R^3.
    """
    sc = case.scene
    vol, th = _volume(case), _mean_angle(case)
    sig = sc.surface_tension
    r_w = 2.0 * sc.reduced_radius if sc.kind == "sphere-sphere" else 2.0 * sc.radius
    _, m_star = _masses(case)
    le = math.log(case.restitution) if case.restitution < 1.0 else 0.0
    kn = (math.pi ** 2 + le * le) * m_star / tc ** 2
    cn = -2.0 * le * m_star / tc
    vs = vol / r_w ** 3
    rupture = (1.0 + 0.5 * th) * (vs ** (1.0 / 3.0) + 0.1 * vs ** (2.0 / 3.0)) * r_w

    def cap(x: float) -> float:
        return -float(willett_force(max(x - x_r, 0.0), vol, r_w, sig, th))

    def contact(d: float, ddot: float) -> float:
        return max(0.0, kn * d + cn * ddot)

    return SetForces({"viscous_rebound": DirectForce("yade-viscelcap", lambda x: dcap),
                      "capillary_rebound": DirectForce("yade-viscelcap", cap)},
                     reach=x_r, rupture=x_r + rupture, volume=vol, contact=contact)


def liggghts_easo(case: CollisionCase, x_r: float, min_separation: float = 0.01
                  ) -> SetForces:
    """LIGGGHTS 3.8.0 ``pair_style gran model hertz tangential history cohesion
    easo/capillary/viscous`` (``normal_model_hertz.h``,
    ``cohesion_model_easo_capillary_viscous.h``):

    - contact: ``F = (4/3) Y* sqrt(R* d) d + 2 sqrt(5/6) |beta| sqrt(2 Y* sqrt(R* d) m*)
      dd/dt``, ``beta = ln e / sqrt(ln^2 e + pi^2)``, not clipped (it pulls at the end);
    - from the first contact, in contact (at s = 0) and apart until rupture: Soulie et
      al.'s ``F = -pi sigma sqrt(R1 R2) (exp(A s/R2 + B) + C)`` (R2 the larger radius,
      ``A = -1.1 V*^-0.53``, ``B = (-0.148 ln V* - 0.96) theta^2 - 0.0082 ln V* + 0.48``,
      ``C = 0.0018 ln V* + 0.078``, V* = V/R2^3) and the viscous
      ``6 pi eta R*^2 v / max(min_separation R*, s)``; nothing on approach;
    - the contact angle is the code's ``0.5 theta1 theta2`` (radians); rupture at
      ``(1 + theta/2) V^(1/3)`` (Lian et al. 1993);
    - on a wall the cohesion model is skipped (its documentation: walls are dry): only the
      contact acts.
    """
    sc = case.scene
    if case.solid.youngs_modulus is None or case.solid2.youngs_modulus is None:
        raise InputError(f"{sc.origin}: solid.youngs_modulus: required by the LIGGGHTS force "
                         "set (its Hertz contact)")
    y_star = 1.0 / ((1 - case.solid.poisson_ratio ** 2) / case.solid.youngs_modulus
                    + (1 - case.solid2.poisson_ratio ** 2) / case.solid2.youngs_modulus)
    _, m_star = _masses(case)
    le = math.log(case.restitution) if case.restitution < 1.0 else 0.0
    beta = le / math.sqrt(le * le + math.pi ** 2)
    rs = sc.reduced_radius

    def contact(d: float, ddot: float) -> float:
        sn = 2.0 * y_star * math.sqrt(rs * d)
        return (4.0 / 3.0 * y_star * math.sqrt(rs * d) * d
                + 2.0 * math.sqrt(5.0 / 6.0) * abs(beta) * math.sqrt(sn * m_star) * ddot)

    if sc.kind == "sphere-wall":  # the cohesion model skips walls: a dry impact
        return SetForces({}, reach=x_r, rupture=x_r, contact=contact)
    vol = _volume(case)
    ang = case.receding_angle or (sc.contact_angle_sphere, sc.contact_angle_wall)
    th = 0.5 * ang[0] * ang[1]
    r1 = sc.radius
    r2 = float(sc.radius2) if sc.kind == "sphere-sphere" else r1
    eta, sig = sc.viscosity, sc.surface_tension
    big = max(r1, r2)
    vs = vol / big ** 3
    a = -1.1 * vs ** -0.53
    b = (-0.148 * math.log(vs) - 0.96) * th * th - 0.0082 * math.log(vs) + 0.48
    c = 0.0018 * math.log(vs) + 0.078
    rupture = (1.0 + 0.5 * th) * vol ** (1.0 / 3.0)

    def cap(x: float) -> float:
        s = max(x - x_r, 0.0)
        return -math.pi * sig * math.sqrt(r1 * r2) * (math.exp(a * s / big + b) + c)

    def visc(x: float) -> float:
        return 6.0 * math.pi * eta * rs * rs / max(min_separation * rs, x - x_r)

    v = DirectForce("liggghts-easo", visc)
    f = DirectForce("liggghts-easo", cap)
    return SetForces({"viscous_approach": v, "viscous_rebound": v, "capillary_approach": f,
                      "capillary_rebound": f}, reach=x_r, rupture=x_r + rupture, volume=vol,
                     contact=contact, cutoff="constant")


FORCE_SETS: dict[str, Callable[..., SetForces]] = {
    "mercurydpm": mercurydpm,
    "reynolds-willett-lian": reynolds_willett_lian,
    "yade-lubrication": yade_lubrication,
    "yade-viscelcap": yade_viscelcap,
    "liggghts-easo": liggghts_easo,
}


def force_set(name: str) -> Callable[..., SetForces]:
    """The force set ``name``, or an InputError listing the known ones."""
    if name not in FORCE_SETS:
        raise InputError(f"force set {name!r}; allowed: " + ", ".join(FORCE_SETS))
    return FORCE_SETS[name]
