"""The equations of one collision: force tables, contact laws and the right-hand side.

The state is ``(x, v, u_t, omega)`` and the work of every mechanism (see
:mod:`wetcontact.collide.impact` for the equations and the phases); :class:`_Impact`
holds the force tables of one collision and evaluates each force at a state and a phase
(:class:`_Mode`). Both integrators use it: the event-driven ``collide`` and the
vectorised ``restitution_map``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wetcontact.collide.case import CollisionCase
from wetcontact.collide.contact import (
    HERTZ_TIME,
    Thornton,
    effective_modulus,
    hertz_damping,
    thornton_yield_pressure,
)
from wetcontact.collide.forces import (
    GapTable,
    bridge_scene,
    gathered_volume,
    pick_model,
    rupture_distance,
    table_for,
)
from wetcontact.errors import InputError

# state layout
(X, V, UT, OM, WVA, WVR, WCAP, WBRI, WCON, WDRAG, WGRAV, WBUOY, WTAN, JN, AVIS,
 ACAP) = range(16)
NSTATE = 16
#: the work of each mechanism: ``capillary`` is the meniscus's before the solid contact
#: (advancing angle), ``bridge`` the bridge's after it (receding angle, until rupture)
_WORK = {"viscous_approach": WVA, "viscous_rebound": WVR, "capillary": WCAP,
         "bridge": WBRI, "contact": WCON, "drag": WDRAG, "gravity": WGRAV,
         "buoyancy": WBUOY, "tangential_viscous": WTAN}


@dataclass
class _Mode:
    """What acts during one segment."""

    name: str
    after_contact: bool = False
    bridge: bool = True            # the bridge exists (not yet ruptured)
    contact: str = ""              # "", "hertz", "thornton-load", "thornton-unload"
    r_p: float = 0.0
    d_p: float = 0.0
    # "dry": above the liquid, no liquid force (the leg's terminal event is the liquid's
    # reach); "clamp": the forces at the rupture gap continue past it (the leg's terminal
    # event is the rupture). Either keeps the right-hand side smooth inside the step that
    # locates the event, so the located state keeps the integrator's order.
    edge: str = ""
    events: list[tuple[str, Any]] = field(default_factory=list)


class _Impact:
    """The equations of one collision with its force tables."""

    def __init__(self, case: CollisionCase, viscous: str | None, capillary: str | None,
                 rtol: float, force_set: str | None = None,
                 force_set_options: dict[str, float] | None = None) -> None:
        sc = case.scene
        self.case, self.rtol = case, rtol
        self.x_r = case.roughness
        self.x0 = case.impact.start_gap
        r1 = sc.radius
        vol1 = 4.0 / 3.0 * math.pi * r1 ** 3
        m1 = case.solid.density * vol1
        if sc.kind == "sphere-wall":
            self.mass = m1
        else:
            m2 = case.solid2.density * 4.0 / 3.0 * math.pi * float(sc.radius2) ** 3
            self.mass = m1 * m2 / (m1 + m2)
        imp = case.impact
        self.m_eff = self.mass + (0.5 * sc.density * vol1 if imp.added_mass else 0.0)
        self.inertia = 0.4 * m1 * r1 * r1
        self.r_star = sc.reduced_radius
        g = sc.gravity
        self.f_grav = -m1 * g if imp.gravity else 0.0
        self.f_buoy = sc.density * vol1 * g if imp.buoyancy else 0.0
        self.oblique = imp.tangential_velocity != 0.0 or imp.spin != 0.0
        if self.oblique and sc.kind != "sphere-wall":
            raise InputError(f"{sc.origin}: impact.tangential_velocity / impact.spin: oblique "
                             "impacts are for sphere-wall scenes; allowed: 0 for two spheres")
        self.tables: dict[str, GapTable] = {}
        self.cutoff = case.cutoff
        self.set_contact: Any = None  # a DEM force set's own contact law
        self.models: dict[str, str | None] = {}
        self.notes: list[str] = []
        if force_set is None:
            self._setup_liquid(viscous, capillary)
        else:
            self._setup_force_set(force_set, force_set_options or {})
        self._setup_contact()

    # ---- forces -------------------------------------------------------------------
    def _setup_liquid(self, viscous: str | None, capillary: str | None) -> None:
        case, sc = self.case, self.case.scene
        base_angles = (sc.contact_angle_sphere, sc.contact_angle_wall)
        adv = case.advancing_angle or base_angles
        rec = case.receding_angle or base_angles
        # a gap inside the liquid's reach for the unit-speed scenes (their gaps are not
        # used); a bridge's default start gap (nan) is its rupture distance, known only
        # below, and beyond 0.1 V^(1/3) (Lian: S_c >= V^(1/3))
        x_unit = (0.1 * float(sc.bridge_volume) ** (1.0 / 3.0) if math.isnan(self.x0)
                  else min(self.x0, sc.radius))
        unit = sc.with_gaps([0.5 * x_unit])
        from dataclasses import replace

        unit = replace(unit, velocity=1.0)
        self.volume = None
        if sc.amount == "immersed":
            app_scene = reb_scene = unit
            self.h_app = math.inf
            self.s_static = math.inf
        else:
            vol = gathered_volume(sc) if sc.amount == "film" else float(sc.bridge_volume)
            self.volume = vol
            app_scene = (replace(unit, contact_angle_sphere=adv[0], contact_angle_wall=adv[1])
                         if sc.amount == "film" else bridge_scene(unit, vol, adv))
            reb_scene = bridge_scene(unit, vol, rec)
        if sc.amount == "immersed" and capillary not in (None, "none"):
            raise InputError(f"--capillary {capillary}: the scene is immersed, no bridge "
                             "forms; allowed: none")
        # rupture distances (static, receding angles) and the liquid's reach on approach
        cmodel = None if sc.amount == "immersed" else pick_model(capillary, reb_scene,
                                                                 "capillary")
        if cmodel is not None:
            self.s_static = rupture_distance(cmodel, reb_scene)
            s_adv = rupture_distance(cmodel, bridge_scene(unit, self.volume, adv))
        elif sc.amount != "immersed":  # no capillary model: Lian et al. 1993
            self.s_static = (1.0 + 0.25 * (rec[0] + rec[1])) * self.volume ** (1.0 / 3.0)
            s_adv = (1.0 + 0.25 * (adv[0] + adv[1])) * self.volume ** (1.0 / 3.0)
        if sc.amount == "film":
            self.h_app = float(sc.film_thickness)
        elif sc.amount == "bridge":
            self.h_app = s_adv
        self._start_gap("")
        shift = self.x_r if case.cutoff == "shifted" else 0.0
        hi_app = min(self.h_app, self.x0) if sc.amount != "immersed" else self.x0
        hi_reb = self.s_static if sc.amount != "immersed" else self.x0
        tabs = self.tables
        if (t := table_for(viscous, app_scene, self.x_r, hi_app + shift, "viscous")):
            tabs["viscous_approach"] = t
            tabs["viscous_rebound"] = t if reb_scene is app_scene else table_for(
                viscous, reb_scene, self.x_r, hi_reb + shift, "viscous")
        if cmodel is not None:
            app_bridge = bridge_scene(unit, self.volume, adv)
            tabs["capillary_approach"] = table_for(
                cmodel.name, app_bridge, self.x_r, min(s_adv, hi_app), "capillary")
            tabs["capillary_rebound"] = table_for(cmodel.name, reb_scene, self.x_r,
                                                  self.s_static, "capillary")
        self.models = {k: (tabs[t].model if t in tabs else None) for k, t in (
            ("viscous", "viscous_approach"), ("viscous_rebound", "viscous_rebound"),
            ("capillary", "capillary_rebound"))}

    def _start_gap(self, of: str) -> None:
        """A bridge's default start gap is its rupture distance; every start gap lies
        beyond the roughness gap (``of``: whose roughness, for the message)."""
        if math.isnan(self.x0):
            self.x0 = self.s_static
        if self.x0 <= self.x_r:
            raise InputError(f"{self.case.scene.origin}: impact.start_gap = {self.x0:.6g} m; "
                             f"allowed: > the roughness gap {self.x_r:.6g} m{of}")

    def _setup_force_set(self, name: str, options: dict[str, float]) -> None:
        from wetcontact.collide.dem import force_set

        build = force_set(name)
        try:
            sf = build(self.case, self.x_r, **options)
        except TypeError:
            raise InputError(f"force set {name!r}: options {sorted(options)}; allowed: the "
                             f"keyword arguments of wetcontact.collide.dem.{build.__name__}"
                             ) from None
        if sf.roughness is not None:
            self.x_r = sf.roughness
            sf = build(self.case, self.x_r, **options)
        if sf.cutoff is not None:
            self.cutoff = sf.cutoff
        self.tables.update(sf.tables)
        self.set_contact = sf.contact
        self.volume, self.h_app, self.s_static = sf.volume, sf.reach, sf.rupture
        self._start_gap(f" of {name}")
        has = {k: k in sf.tables for k in ("viscous_approach", "viscous_rebound",
                                           "capillary_rebound")}
        self.models = {"viscous": name if has["viscous_approach"] else None,
                       "viscous_rebound": name if has["viscous_rebound"] else None,
                       "capillary": name if has["capillary_rebound"] else None,
                       "force_set": name}

    def _setup_contact(self) -> None:
        case = self.case
        self.e_dry = case.restitution
        self.k = self.alpha = 0.0
        self.thornton: Thornton | None = None
        if case.contact_model == "impulse":
            return
        e1, e2 = case.solid.youngs_modulus, case.solid2.youngs_modulus
        self.e_star = effective_modulus(float(e1), case.solid.poisson_ratio, float(e2),
                                        case.solid2.poisson_ratio)
        self.k = 4.0 / 3.0 * self.e_star * math.sqrt(self.r_star)
        if case.contact_model == "hertz":
            self.alpha = hertz_damping(self.e_dry)
        else:
            p_y = thornton_yield_pressure(self.e_star, self.r_star, self.m_eff,
                                          case.impact.velocity, self.e_dry)
            self.thornton = Thornton(self.e_star, self.r_star, p_y)

    def dry_contact_time(self, v: float) -> float:
        """Hertz contact time of an undamped dry impact at ``v`` (m/s)."""
        return HERTZ_TIME * (self.m_eff ** 2 / (self.r_star * self.e_star ** 2 * v)) ** 0.2

    def viscous_unit(self, x: float, v: float, mode: _Mode) -> float:
        """Viscous force per unit speed at gap x (N s/m), with the cut-off and the
        dynamic bridge's stretch."""
        key = "viscous_rebound" if mode.after_contact else "viscous_approach"
        tab = self.tables.get(key)
        if tab is None or mode.edge == "dry" or (
                not mode.bridge and self.case.scene.amount != "immersed"):
            return 0.0
        if v < 0.0 and not self.case.viscous_on_rebound:
            return 0.0
        cut = self.cutoff
        if cut == "shifted":
            xe = max(x, 0.0) + self.x_r
        elif x < self.x_r:
            if cut == "zero":
                return 0.0
            xe = self.x_r
        else:
            xe = x
        if mode.after_contact:
            xe = xe / self.stretch(v)  # 1 for a static rupture
        reach = (self.h_app if not mode.after_contact else
                 (self.s_static if self.case.scene.amount != "immersed" else math.inf))
        if cut == "shifted":
            reach += self.x_r
        if xe > reach:  # closed at the reach: its inside value there
            return tab(reach) if mode.edge == "clamp" else 0.0
        return tab(xe)

    def stretch(self, v: float) -> float:
        """Pitois' factor ``1 + Ca^1/2`` at the separation speed (1 for a static law)."""
        if self.case.rupture != "dynamic":
            return 1.0
        sc = self.case.scene
        return 1.0 + math.sqrt(sc.viscosity * abs(v) / sc.surface_tension)

    def capillary(self, x: float, v: float, mode: _Mode) -> float:
        """Capillary force (N) of the bridge at gap x, zero where there is none."""
        if not mode.bridge or mode.edge == "dry":
            return 0.0
        if mode.after_contact:
            tab = self.tables.get("capillary_rebound")
            if tab is None:
                return 0.0
            xe = x / self.stretch(v)
            if xe > self.s_static:
                return tab(self.s_static) if mode.edge == "clamp" else 0.0
            return tab(xe)
        tab = self.tables.get("capillary_approach")
        if tab is None or x > min(self.h_app, tab.hi):
            return 0.0
        return tab(x)

    def contact_force(self, x: float, v: float, mode: _Mode) -> float:
        """Solid contact force (N) at overlap ``x_r - x``."""
        d = self.x_r - x
        if not mode.contact or d <= 0.0:
            return 0.0
        if mode.contact == "set":
            assert self.set_contact is not None
            return self.set_contact(d, v)
        if mode.contact == "hertz":
            return max(0.0, self.k * d ** 1.5 + self.alpha * math.sqrt(self.m_eff * self.k)
                       * d ** 0.25 * v)
        assert self.thornton is not None
        if mode.contact == "thornton-load":
            return self.thornton.loading(d)
        return self.thornton.unloading_force(d, mode.r_p, mode.d_p)

    def drag(self, v: float) -> float:
        """Far-field quasi-steady drag beyond Stokes' (N): Schiller & Naumann's
        ``6 pi eta R v 0.15 Re^0.687``, Re = 2 R rho |v| / eta; plus the Stokes drag
        ``6 pi eta R v`` where the viscous model is a thin-gap closure without it."""
        if not self.case.impact.drag:
            return 0.0
        sc = self.case.scene
        re = 2.0 * sc.radius * sc.density * abs(v) / sc.viscosity
        stokes = 6.0 * math.pi * sc.viscosity * sc.radius * v
        thin = self.models["viscous"] in (None, "reynolds", "reynolds-finite", "vinogradova")
        return stokes * (0.15 * re ** 0.687 + (1.0 if thin else 0.0))

    def tangential(self, x: float, ut: float, om: float, mode: _Mode) -> tuple[float, float]:
        """Tangential lubrication force (N) and torque (N m) near the wall."""
        if not self.oblique or "viscous_approach" not in self.tables:
            return 0.0, 0.0
        sc = self.case.scene
        reach = self.h_app if not mode.after_contact else self.s_static
        if sc.amount != "immersed" and (x >= reach or not mode.bridge):
            return 0.0, 0.0
        r = sc.radius
        lg = math.log(r / max(x, self.x_r))
        f = -6.0 * math.pi * sc.viscosity * r * ut * (8.0 / 15.0 * lg + 0.9588)
        t = -8.0 * math.pi * sc.viscosity * r ** 3 * om * (0.4 * lg + 0.3817)
        return f, t

    def forces(self, y: np.ndarray, mode: _Mode) -> dict[str, float]:
        x, v = float(y[X]), float(y[V])
        fv = v * self.viscous_unit(x, v, mode)
        ft, tq = self.tangential(x, float(y[UT]), float(y[OM]), mode)
        return {"viscous": fv, "capillary": self.capillary(x, v, mode),
                "contact": self.contact_force(x, v, mode), "drag": self.drag(v),
                "gravity": self.f_grav, "buoyancy": self.f_buoy, "tangential": ft,
                "torque": tq}

    def rhs(self, _t: float, y: np.ndarray, mode: _Mode) -> np.ndarray:
        f = self.forces(y, mode)
        v = float(y[V])
        total = (f["viscous"] + f["capillary"] + f["contact"] + f["drag"] + f["gravity"]
                 + f["buoyancy"])
        dy = np.zeros(NSTATE)
        dy[X] = -v
        dy[V] = -total / self.m_eff
        dy[UT] = f["tangential"] / self.m_eff
        dy[OM] = f["torque"] / self.inertia
        dy[WVA if v >= 0.0 else WVR] = f["viscous"] * v
        dy[WBRI if mode.after_contact else WCAP] = f["capillary"] * v
        dy[WCON] = f["contact"] * v
        dy[WDRAG] = f["drag"] * v
        dy[WGRAV] = f["gravity"] * v
        dy[WBUOY] = f["buoyancy"] * v
        dy[WTAN] = -(f["tangential"] * float(y[UT]) + f["torque"] * float(y[OM]))
        dy[JN] = f["contact"]
        dy[AVIS] = abs(f["viscous"] * v)  # absolute works: the tables' error bound on e
        dy[ACAP] = abs(f["capillary"] * v)
        return dy

    def kinetic(self, y: np.ndarray) -> float:
        return 0.5 * (self.m_eff * (y[V] ** 2 + y[UT] ** 2) + self.inertia * y[OM] ** 2)


