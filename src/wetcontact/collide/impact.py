"""One wet impact through its phases: penetration, solid contact, emergence, bridge.

Normal motion of the gap x with the approach speed ``v = -dx/dt`` (positive = toward):

    m* dv/dt = -(F_v + F_c + F_s + F_far),   F_v = v f1(x),

each force on the sphere, positive = pushing the surfaces apart (the toolkit's sign
convention): ``f1`` the viscous force at unit speed, ``F_c`` the capillary force of the
bridge, ``F_s`` the solid contact (``wetcontact.collide.contact``), ``F_far`` gravity,
buoyancy and the far-field drag. ``m*`` is ``m1 m2/(m1 + m2)`` (a wall: m), plus
``rho_f V_p / 2`` with added mass. The work of each force, ``W_i = int F_i v dt``, is
integrated with the motion, so ``KE_0 = KE_end + sum W_i`` is an identity of the equations
that the numbers check (``energy_residual``). Oblique impacts on a wall add the tangential
lubrication force ``F_t = -6 pi eta R u_t (8/15 ln(R/x) + 0.9588)`` and the rotational
torque ``T = -8 pi eta R^3 omega (2/5 ln(R/x) + 0.3817)`` (Goldman, Cox & Brenner 1967;
their coupling terms are left out), and at the solid contact Coulomb's impulse balance
(eqs. 1.5-1.6 of the seed thesis): the contact point sticks when the impulse that stops
its slip, ``(2/7) m u_s``, is below ``mu J_n``, else slides with ``mu J_n``.

Phases are separated by located events (contact start and end, the film surface, the
rupture distance, the turning point, the start gap); each segment between events is
integrated by scipy's DOP853 (explicit Runge-Kutta of order 8, Hairer & Wanner) with its
own right-hand side, so no force is discontinuous inside a step.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from wetcontact.collide.case import CollisionCase
from wetcontact.collide.equations import (
    _WORK,
    ACAP,
    AVIS,
    JN,
    NSTATE,
    OM,
    UT,
    WCON,
    V,
    X,
    _Impact,
    _Mode,
)
from wetcontact.collide.result import Collision, Phase
from wetcontact.errors import InputError, SolverError
from wetcontact.models import provenance

#: declared order of the collision's outputs: DOP853 steps at order 8, and the phase
#: events are located on its dense output, of order 7, which sets the order of every
#: quantity read at an event (contact speed, rebound speed, phase times)
ORDER = 7
#: default relative tolerance of the integrator
RTOL = 1e-10
#: the approach counts as arrested (stick) when its speed falls below this fraction of v0
ARREST = 1e-9


def _event(fn: Any, direction: int, terminal: bool = True) -> Any:
    fn.direction, fn.terminal = direction, terminal
    return fn


class _Run:
    """The segment loop: integrate, stop at an event, change the mode, go on."""

    def __init__(self, imp: _Impact, max_step: float, fixed: bool) -> None:
        self.imp = imp
        c = imp.case.impact
        self.y = np.zeros(NSTATE)
        self.y[X], self.y[V], self.y[UT], self.y[OM] = imp.x0, c.velocity, \
            c.tangential_velocity, c.spin
        self.t = 0.0
        self.ke0 = imp.kinetic(self.y)
        self.phases: list[Phase] = []
        self.ts: list[np.ndarray] = []
        self.ys: list[np.ndarray] = []
        self.modes: list[_Mode] = []
        self.steps = 0
        self.v_contact: float | None = None
        self.v_rebound: float | None = None
        self.u_slip0 = c.tangential_velocity + imp.case.scene.radius * c.spin
        self.u_slip_rebound: float | None = None
        self.stick_reason = ""
        self.max_step, self.fixed = max_step, fixed
        tmax_scale = imp.x0 / max(c.velocity, 1e-300)
        self.t_guard = 1e6 * tmax_scale

    def segment(self, mode: _Mode, events: dict[str, Any]) -> str:
        """Integrate in ``mode`` until one of ``events`` (name -> (fn, direction)); returns
        the name of the event that ended it."""
        imp = self.imp
        names = list(events)
        fns = [_event(lambda t, y, *_args, f=fn: f(y), d, term)
               for (fn, d, term) in events.values()]
        scale = np.full(NSTATE, max(self.ke0, 1e-300))
        scale[X] = imp.x0
        scale[V] = scale[UT] = max(imp.case.impact.velocity, 1e-300)
        scale[OM] = max(abs(imp.case.impact.spin), imp.case.impact.velocity
                        / imp.case.scene.radius)
        scale[JN] = imp.m_eff * imp.case.impact.velocity
        opts: dict[str, Any] = {"rtol": imp.rtol, "atol": imp.rtol * scale}
        if self.fixed:
            opts = {"rtol": 1e3, "atol": 1e3 * scale, "first_step": self.max_step}
        sol = solve_ivp(imp.rhs, (self.t, self.t + self.t_guard), self.y, method="DOP853",
                        events=fns, args=(mode,), max_step=self.max_step, **opts)
        if sol.status == -1:
            raise SolverError(f"collide: the integrator failed in phase '{mode.name}': "
                              f"{sol.message}")
        self.steps += sol.t.size - 1
        ended = ""
        for i, name in enumerate(names):
            if sol.t_events[i].size and events[name][2]:
                ended = name
                t_end, y_end = float(sol.t_events[i][-1]), sol.y_events[i][-1].copy()
                break
        else:
            t_end, y_end = float(sol.t[-1]), sol.y[:, -1].copy()
            ended = "time"
        # non-terminal: the start gap crossed on rebound
        if "start_gap" in events and not events["start_gap"][2]:
            k = names.index("start_gap")
            if sol.t_events[k].size and self.v_rebound is None:
                self.v_rebound = float(sol.y_events[k][0][V])
                self.u_slip_rebound = float(sol.y_events[k][0][UT] + imp.case.scene.radius
                                            * sol.y_events[k][0][OM])
        keep = sol.t < t_end
        self.ts.append(np.append(sol.t[keep], t_end))
        self.ys.append(np.column_stack([sol.y[:, keep], y_end]))
        self.modes.append(mode)
        self.phases.append(Phase(mode.name, self.t, t_end))
        self.t, self.y = t_end, y_end
        return ended

    def friction_impulse(self) -> None:
        """Coulomb's impulse balance at the end of the solid contact (eqs. 1.5-1.6)."""
        imp = self.imp
        if not imp.oblique:
            return
        r = imp.case.scene.radius
        u_s = float(self.y[UT] + r * self.y[OM])
        inv = 1.0 / imp.m_eff + r * r / imp.inertia
        j_stick = u_s / inv
        j_max = imp.case.friction * float(self.y[JN])
        j = j_stick if abs(j_stick) <= j_max else math.copysign(j_max, u_s)
        ke = imp.kinetic(self.y)
        self.y[UT] -= j / imp.m_eff
        self.y[OM] -= j * r / imp.inertia
        self.friction_work = ke - imp.kinetic(self.y)
        self.sticking = abs(j_stick) <= j_max


def collide(case: CollisionCase, viscous: str | None = None, capillary: str | None = None,
            rtol: float = RTOL, max_step: float = math.inf, fixed_step: bool = False,
            trajectory: bool = True, force_set: str | None = None,
            tol: float | None = None,
            force_set_options: dict[str, float] | None = None) -> Collision:
    """Integrate one wet impact and return its outcome.

    Parameters
    ----------
    case
        The collision (:func:`wetcontact.collide.load_collision_case`).
    viscous, capillary
        Force model names (``wetcontact models``), ``"none"`` to switch a component off,
        or None for the defaults (the calibrated closures where they accept the scene,
        the solvers or the published closures elsewhere).
    rtol
        Relative tolerance of the integrator (DOP853); the restitution's error follows it
        (``benchmarks/bench_collide.py`` charts error against time).
    max_step, fixed_step
        Largest time step (s); with ``fixed_step`` every step is ``max_step`` (for the
        convergence-order test).
    trajectory
        Keep the time series (time, gap, velocity, forces) in the result.
    force_set
        A DEM code's force set (:data:`wetcontact.collide.dem.FORCE_SETS`) instead of the
        toolkit's models (``viscous`` and ``capillary`` are then ignored).
    force_set_options
        Settings of the force set that the case does not carry (e.g. Yade's contact time
        ``tc``), as keyword arguments of its function in :mod:`wetcontact.collide.dem`.
    tol
        Absolute tolerance on e: the cheapest models whose measured restitution error
        meets it (:func:`wetcontact.collide.tolerance.choose`; ``models["tolerance"]``
        gives the bound and why); not with ``viscous``, ``capillary`` or ``force_set``.

    Returns
    -------
    Collision
        Restitution, outcome, phases, energy budget, models and diagnostics.

    Raises
    ------
    InputError
        A model that does not apply (the message names the one that does).
    SolverError
        The integrator failed.
    """
    import time

    if not isinstance(case, CollisionCase):
        raise InputError(f"collide: case = {type(case).__name__}; allowed: a CollisionCase "
                         "(wetcontact.collide.load_collision_case, or collision_case(scene, "
                         "impact={...}, solid={...}) for a Scene)")
    chosen: dict[str, Any] | None = None
    if tol is not None:
        if viscous is not None or capillary is not None or force_set is not None:
            raise InputError("collide: tol picks the models; allowed: tol without viscous, "
                             "capillary or force_set")
        if isinstance(tol, bool) or not isinstance(tol, int | float) or not 0.0 < tol < 1.0:
            raise InputError(f"collide: tol = {tol!r}; allowed: a number in (0, 1)")
        from wetcontact.collide.tolerance import choose

        sc = case.scene
        m_st = case.solid.density * 4.0 / 3.0 * math.pi * sc.radius ** 3
        st = m_st * case.impact.velocity / (6.0 * math.pi * sc.viscosity
                                            * sc.reduced_radius ** 2)
        viscous, capillary, chosen = choose(case, float(tol), st)
    t0 = time.perf_counter()
    imp = _Impact(case, viscous, capillary, rtol, force_set, force_set_options)
    if chosen is not None:
        imp.models["tolerance"] = chosen  # type: ignore[assignment]
    t_tab = time.perf_counter() - t0
    run = _Run(imp, max_step, fixed_step)
    run.friction_work = 0.0
    run.sticking = False
    run.ruptured = False
    sc = case.scene
    v0 = case.impact.velocity
    x_r, x0 = imp.x_r, imp.x0

    def gap_at(level: float) -> Any:
        return lambda y: y[X] - level

    def speed_at(level: float) -> Any:
        return lambda y: y[V] - level

    outcome = "rebound"
    # -- approach above the liquid (a start gap beyond the film or the bridge's reach)
    mode = _Mode("approach", edge="dry")
    dry_approach = imp.h_app <= x_r  # liquid forces only after the first contact
    if x0 > imp.h_app:
        level = x_r if dry_approach else imp.h_app
        ev = run.segment(mode, {"liquid": (gap_at(level), -1, True),
                                "turn": (speed_at(0.0), -1, True)})
        if ev != "liquid":
            outcome, run.stick_reason = "stick", "turned before reaching the liquid"
        elif dry_approach:
            run.v_contact = float(run.y[V])
    # -- penetration of the liquid to the roughness gap
    if outcome == "rebound" and not dry_approach:
        mode = _Mode("penetration")
        ev = run.segment(mode, {"contact": (gap_at(x_r), -1, True),
                                "arrest": (speed_at(ARREST * v0), -1, True)})
        if ev != "contact":
            outcome, run.stick_reason = "stick", "arrested before solid contact"
        else:
            run.v_contact = float(run.y[V])
    # -- solid contact
    if outcome == "rebound":
        vc = float(run.y[V])
        if imp.set_contact is not None:
            ev = run.segment(_Mode("contact", contact="set"),
                             {"separation": (gap_at(x_r), 1, True)})
            if ev != "separation":
                outcome, run.stick_reason = "stick", "held in solid contact"
        elif case.contact_model == "impulse":
            run.y[WCON] += 0.5 * imp.m_eff * vc * vc * (1.0 - imp.e_dry ** 2)
            run.y[JN] += imp.m_eff * (1.0 + imp.e_dry) * vc
            run.y[V] = -imp.e_dry * vc
            run.phases.append(Phase("contact", run.t, run.t))
        elif case.contact_model == "hertz":
            ev = run.segment(_Mode("contact", contact="hertz"),
                             {"separation": (gap_at(x_r), 1, True)})
            if ev != "separation":
                outcome, run.stick_reason = "stick", "held in solid contact"
        else:
            ev = run.segment(_Mode("contact", contact="thornton-load"),
                             {"turn": (speed_at(0.0), -1, True)})
            assert imp.thornton is not None
            r_p, d_p = imp.thornton.unloading(x_r - float(run.y[X]))
            ev = run.segment(_Mode("contact", contact="thornton-unload", r_p=r_p, d_p=d_p),
                             {"separation": (gap_at(x_r - d_p), 1, True),
                              "turn": (speed_at(0.0), 1, True)})
            if ev != "separation":
                outcome, run.stick_reason = "stick", "held in solid contact"
            run.phases[-2:] = [Phase("contact", run.phases[-2].start, run.phases[-1].end)]
        run.friction_impulse()
    # -- emergence, bridge, departure
    if outcome == "rebound":
        recontact = (gap_at(x_r - 1e-12 * x_r), -1, True)
        captured = (speed_at(0.0), 1, True)
        start = (gap_at(x0), 1, False)
        # (phase, gap where it ends); nan: the bridge's static or dynamic rupture
        legs: list[tuple[str, float]] = []
        if sc.amount == "immersed":
            legs.append(("emergence", x0))
        else:
            if sc.amount == "film":
                legs.append(("emergence", float(sc.film_thickness)))
            legs += [("bridge", math.nan), ("departure", x0)]
        bridge = True
        for name, level in legs:
            reached = (imp.s_static * imp.stretch(float(run.y[V])) if math.isnan(level)
                       else level)
            if float(run.y[X]) >= reached:
                bridge = bridge and not math.isnan(level)
                continue
            mode = _Mode(name, after_contact=True, bridge=bridge,
                         edge="clamp" if name == "bridge" else "")
            if name == "bridge" and math.isnan(level):
                events = {"end": (lambda y: y[X] - imp.s_static * imp.stretch(y[V]), 1, True)}
            else:
                events = {"end": (gap_at(level), 1, True)}
            events.update({"captured": captured, "recontact": recontact})
            if name != "departure":
                events["start_gap"] = start
            ev = run.segment(mode, events)
            if ev != "end":
                outcome = "stick"
                run.stick_reason = ("turned back before escaping" if ev == "captured" else
                                    "returned to solid contact" if ev == "recontact" else
                                    "did not escape in time")
                break
            if name == "bridge":
                bridge = False
                run.ruptured = True
            if run.v_rebound is None and math.isclose(level, x0, rel_tol=1e-12):
                # the leg ended at the start gap (its terminal event located it)
                run.v_rebound = float(run.y[V])
                run.u_slip_rebound = float(run.y[UT] + sc.radius * run.y[OM])
    if (outcome == "rebound" and run.v_rebound is None
            and float(run.y[X]) >= x0 * (1.0 - 1e-9)):
        # the last leg ended on the start gap itself (a bridge started at its rupture
        # distance: the rupture event and the start gap coincide)
        run.v_rebound = float(run.y[V])
        run.u_slip_rebound = float(run.y[UT] + sc.radius * run.y[OM])
    t_int = time.perf_counter() - t0 - t_tab
    return _result(case, imp, run, outcome, t_tab, t_int, trajectory)


def liquid_division(case: CollisionCase, volume: float) -> tuple[float, str]:
    """Fraction of the bridge's liquid that body 1 (the sphere) keeps at rupture, and its
    source: the quasi-static division of the critical bridge cut at its neck
    (:func:`wetcontact.solver.meniscus.division.transfer_fraction`, receding angles; about
    0.2 s, kept per geometry), or an even split where the meniscus solver refuses the
    bridge (the reason is in the source)."""
    from dataclasses import replace

    from wetcontact.collide.forces import bridge_scene

    sc = case.scene
    rec = case.receding_angle or (sc.contact_angle_sphere, sc.contact_angle_wall)
    scene = bridge_scene(replace(sc, gaps=(sc.gaps[0],), velocity=1.0), volume, rec)
    return _division(scene)


@lru_cache(maxsize=128)
def _division(scene: Any) -> tuple[float, str]:
    from wetcontact.solver.meniscus.division import transfer_fraction
    from wetcontact.solver.meniscus.geometry import Bridge

    try:
        div = transfer_fraction(Bridge.from_scene(scene), float(scene.bridge_volume))
    except (InputError, SolverError) as exc:
        return 0.5, f"even split: the meniscus solver refuses the bridge ({exc})"
    return float(div.fraction), f"meniscus: the critical bridge cut at its neck ({div.neck})"


def _result(case: CollisionCase, imp: _Impact, run: _Run, outcome: str, t_tab: float,
            t_int: float, trajectory: bool) -> Collision:
    sc, v0 = case.scene, case.impact.velocity
    y = run.y
    work = {k: float(y[i]) for k, i in _WORK.items()}
    work["friction"] = run.friction_work
    ke_end = imp.kinetic(y)
    energy = {"impact": run.ke0, "rebound": ke_end, **{k: w for k, w in work.items()
                                                       if w != 0.0}}
    residual = (run.ke0 - ke_end - sum(work.values())) / run.ke0
    # a force table off by eps (relative to its largest magnitude, which bounds the local
    # force) changes the kinetic energy by at most eps times the force's absolute work
    ierr = {k: t.interpolation_error for k, t in imp.tables.items()}
    d_ke = (max((v for k, v in ierr.items() if k.startswith("viscous")), default=0.0)
            * float(y[AVIS]) + max((v for k, v in ierr.items() if k.startswith("capillary")),
                                   default=0.0) * float(y[ACAP]))
    if outcome == "rebound" and run.v_rebound is not None:
        e = -run.v_rebound / v0
    else:
        e, outcome = 0.0, "stick"
    e_t = angle = None
    if imp.oblique and outcome == "rebound":
        u_s = run.u_slip_rebound if run.u_slip_rebound is not None else float(
            y[UT] + sc.radius * y[OM])
        e_t = u_s / run.u_slip0 if run.u_slip0 else None
        angle = math.degrees(math.atan2(abs(float(y[UT])), abs(float(run.v_rebound))))
    traj: dict[str, np.ndarray] = {}
    if trajectory and run.ts:
        t = np.concatenate(run.ts)
        ys = np.concatenate(run.ys, axis=1)
        fs = [imp.forces(seg[:, j], m) for seg, m in zip(run.ys, run.modes, strict=True)
              for j in range(seg.shape[1])]
        traj = {"time": t, "gap": ys[X], "velocity": ys[V],
                "force_viscous": np.array([f["viscous"] for f in fs]),
                "force_capillary": np.array([f["capillary"] for f in fs]),
                "force_contact": np.array([f["contact"] for f in fs])}
        if imp.oblique:
            traj["tangential_velocity"] = ys[UT]
            traj["spin"] = ys[OM]
    st = imp.mass * v0 / (6.0 * math.pi * sc.viscosity * imp.r_star ** 2)
    diag = {"energy_residual": residual, "steps": run.steps,
            "interpolation_error": ierr,
            "restitution_interpolation_bound": (0.5 * e * d_ke / ke_end if ke_end > 0.0
                                                else 0.0),
            "table_nodes": {k: t.nodes for k, t in imp.tables.items()},
            "table_time_s": t_tab, "integration_time_s": t_int,
            "integrator": {"method": "DOP853", "order": ORDER, "rtol": imp.rtol}}
    if run.stick_reason:
        diag["stick_reason"] = run.stick_reason
    liquid: dict[str, Any] = {}
    if imp.volume is not None:
        liquid["bridge_volume"] = imp.volume
        liquid["rupture_distance_static"] = imp.s_static
        if run.ruptured:
            frac, source = liquid_division(case, imp.volume)
            liquid.update(transfer_fraction=frac, body1=frac * imp.volume,
                          body2=(1.0 - frac) * imp.volume, transfer_source=source)
    settings = {"contact": case.contact_model, "cutoff": case.cutoff,
                "viscous_on_rebound": case.viscous_on_rebound, "rupture": case.rupture,
                "start_gap": imp.x0, "roughness": imp.x_r, "restitution_dry": imp.e_dry,
                "velocity": v0, "rtol": imp.rtol}
    from wetcontact.collide.validity import validity_notes

    return Collision(
        case=sc.name, restitution=e, outcome=outcome, contact_velocity=run.v_contact,
        rebound_velocity=(-run.v_rebound if run.v_rebound is not None else None),
        phases=tuple(run.phases), energy=energy, models=dict(imp.models),
        stokes_number=st, tangential_restitution=e_t, rebound_angle=angle,
        liquid=liquid, validity=tuple(validity_notes(case, imp.x0)), settings=settings,
        diagnostics=diag, provenance=provenance(), trajectory=traj)
