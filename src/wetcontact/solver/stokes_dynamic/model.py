r"""The registered ``stokes-dynamic`` model: a liquid bridge moved at the scene's speed.

The bridge starts as the static meniscus (``meniscus``) at the first gap of the scene (or at
``start``, S/R) and moves at the constant relative speed ``v`` of the scene (approach for
v > 0, separation for v < 0; capillary number ``Ca = eta |v| / sigma``), solved by
free-surface Stokes flow (:func:`.run.run`, units R, sigma, eta; SI on output). The gaps
must follow the motion (increasing when separating, decreasing when approaching).

Forces at each gap, on the (first) sphere, positive pushing the solids apart:

- ``force_total`` (``force_capillary + force_viscous``): the reaction of the solid
  tractions and the interface's pull at the contact line (:mod:`.step`), interpolated from
  the run's states (a cubic spline in the gap; between the last state and the pinch,
  linearly to zero force at the pinch, where the thread's tension ``~ sigma h`` vanishes);
- ``force_capillary``: the quasi-static capillary force of ``meniscus`` at the same gap and
  volume (zero where no static bridge exists, past the static fold);
- ``force_viscous``: the rest, the dynamic excess (at small Ca, Ca times ``stokes``'
  quasi-static bridge force per unit speed).

Past the pinch both are zero (``bridge_exists`` 0). Extras: ``neck_radius`` (m),
``bridge_exists``; when the bridge pinched, ``rupture_distance`` (m, the gap at the pinch,
:func:`.pinch.locate_pinch`) and ``transfer_fraction`` (the sphere's share of the liquid at
the pinch; :mod:`.division`; 1/2 between equal spheres).

Geometries: sphere-wall and two spheres (R2/R in
:data:`~.rupture.RADIUS_RATIO_RANGE`), angles and slip lengths may differ on the two
solids. Equal spheres with equal angles and slip lengths are solved on the half above the
shear-free mid-plane, other pairs on the whole bridge (the lower sphere a solid at rest
with slip and a contact line; the two agree within 8e-5 on the rupture distance at
Ca = 1e-2). Accuracy:
:mod:`wetcontact.solver.stokes_dynamic` (force at Ca = 1e-4 within 1.7e-5 of ``meniscus``
plus Ca times ``stokes`` up to 0.08 R; the rupture distance: :mod:`.rupture`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.scene import Scene
from wetcontact.solver.meniscus import Bridge, rupture_distance
from wetcontact.solver.stokes_dynamic.division import wall_fraction
from wetcontact.solver.stokes_dynamic.domain import Domain, MeshOptions
from wetcontact.solver.stokes_dynamic.pinch import locate_pinch
from wetcontact.solver.stokes_dynamic.run import ORDER, DynamicRun, Stepping, run
from wetcontact.solver.stokes_dynamic.rupture import (
    CA_RANGE,
    NECK_STOP,
    PAIR_THETA_MAX,
    PRESETS,
    RADIUS_RATIO_RANGE,
    THETA_RANGE,
    VOLUME_RANGE,
    scaled_gap_step,
)
from wetcontact.solver.stokes_dynamic.step import LINE_LAWS, StepSolution, Wetting

FORCE_GAP_STEPS = {"fast": 7e-4, "default": 5e-4, "accurate": 2.5e-4}
"""The largest gap step (R, at S_c = 0.11 R and Ca >= 1e-2) of each preset: the force's
time error (``benchmarks/bench_dynamic_rupture.py``)."""

SLIP_RANGE = (1e-5, 1e-2)
"""Slip lengths b/R the contact-line elements (1e-3 R) resolve."""
DEFAULT_SLIP = 1e-3
"""b/R a solid with zero slip length gets (a moving contact line needs slip)."""
MIN_GAP = 1e-3
"""Smallest S/R (the gap's elements)."""


QUASI_STATIC = "; quasi-static: stokes (viscous) with meniscus (capillary)"


def _instead(scene: Scene) -> str | None:
    """The model named in a refusal: ``meniscus``, the static bridge, when it accepts the
    scene (the quasi-static viscous part is ``stokes``'); no search over every model (their
    own refusals would search back)."""
    from wetcontact.models import MODELS

    return "meniscus" if MODELS["meniscus"].applicable(scene) is None else None


@register
class StokesDynamic(Model):
    """Free-surface Stokes flow of a liquid bridge moved at the scene's speed (ALE
    Taylor-Hood, BDF2, gmsh remeshing; :mod:`wetcontact.solver.stokes_dynamic`).

    Options: ``start`` (S/R at which the static bridge starts moving; default the first
    gap), ``gap_step`` (the largest gap step, R, at S_c = 0.11 R and Ca >= 1e-2, shorter
    like Ca^(1/3) below, :func:`.rupture.scaled_gap_step`), ``neck_step`` (largest relative
    change of the neck per step) and ``tolerance`` (the neck's local error per step,
    ``Stepping.tolerance``) from the preset, ``default_slip`` (b/R for a solid whose slip
    length is 0), ``save_fields`` (a folder: the velocity and pressure at the first state at
    or past each gap, VTU files and a ParaView collection), ``checkpoint`` (a ``.npz`` file:
    a killed run resumes from it), ``line`` (the contact-line law: ``"static"``, ``"cox-voinov"``
    or ``"pinned"``, :class:`~.step.Wetting`), ``macro_length`` (m, Cox-Voinov's L;
    default the sphere radius) and ``trajectory`` (a motion instead of the scene's constant
    speed: ``{"time": [...], "gap": [...]}`` in s and m, e.g. a collision's
    ``Collision.trajectory`` from the solid contact on; the gap strictly monotone in time,
    interpolated by a monotone cubic (PCHIP); the bridge starts static at its first gap).
    """

    name = "stokes-dynamic"
    level = 3
    component = "both"
    validity = (f"a moving liquid bridge, Ca = eta|v|/sigma in [{CA_RANGE[0]:g}, "
                f"{CA_RANGE[1]:g}], V/R^3 in [{VOLUME_RANGE[0]:g}, {VOLUME_RANGE[1]:g}], contact "
                f"angles {THETA_RANGE[0]:g}-{THETA_RANGE[1]:g} deg; sphere-wall, or two "
                f"spheres (R2/R {RADIUS_RATIO_RANGE[0]:g}-{RADIUS_RATIO_RANGE[1]:g}, angles "
                f"<= {PAIR_THETA_MAX:g} deg); slip "
                f"b/R in [{SLIP_RANGE[0]:g}, {SLIP_RANGE[1]:g}] (0: {DEFAULT_SLIP:g}); S/R >= "
                f"{MIN_GAP:g}")
    order = float(ORDER)
    saves_fields = True
    selectable = False
    cost = 60.0
    reference = ("ALE free-surface Stokes (Taylor-Hood P2/P1, scikit-fem), Baensch's "
                 "semi-implicit curvature, BDF2, gmsh remeshing")
    source = ("free-surface Stokes flow of a moving bridge; checked against the static "
              "meniscus, the quasi-static stokes bridge (Ca -> 0), Papageorgiou 1995 (the "
              "neck's pinch-off rate) and Pitois, Moucheront & Chateau 2001 (rupture)")
    presets: ClassVar[dict[str, dict[str, Any]]] = {
        p: {"gap_step": FORCE_GAP_STEPS[p], "neck_step": PRESETS[p].neck_step,
            "tolerance": PRESETS[p].tolerance, "default_slip": DEFAULT_SLIP}
        for p in PRESETS}

    def check(self, scene: Scene) -> None:
        if scene.amount != "bridge":
            raise ValidityError(self.name, f"amount = {scene.amount!r}: a liquid bridge only",
                                _instead(scene))
        R = scene.radius
        if scene.velocity == 0.0:
            raise ValidityError(self.name, "velocity = 0: a static bridge (use meniscus)",
                                "meniscus")
        ca = scene.viscosity * abs(scene.velocity) / scene.surface_tension
        if not CA_RANGE[0] <= ca <= CA_RANGE[1]:
            raise ValidityError(self.name, f"Ca = eta|v|/sigma = {ca:.3g} outside [{CA_RANGE[0]:g}"
                                f", {CA_RANGE[1]:g}] (above, the stretched thread's mesh fails)",
                                _instead(scene))
        v = scene.bridge_volume / R**3
        if not VOLUME_RANGE[0] <= v <= VOLUME_RANGE[1]:
            raise ValidityError(self.name, f"V/R^3 = {v:.3g} outside [{VOLUME_RANGE[0]:g}, "
                                f"{VOLUME_RANGE[1]:g}]", _instead(scene))
        angles = {"contact_angle_sphere": scene.contact_angle_sphere,
                  "contact_angle_wall": scene.contact_angle_wall}
        for label, th in angles.items():
            deg = math.degrees(th)
            if not THETA_RANGE[0] <= deg <= THETA_RANGE[1] + 1e-9:
                raise ValidityError(self.name, f"{label} = {deg:.4g} deg outside "
                                    f"[{THETA_RANGE[0]:g}, {THETA_RANGE[1]:g}] deg",
                                    _instead(scene))
        slips = {"slip_length_sphere": scene.slip_length_sphere,
                 "slip_length_wall": scene.slip_length_wall}
        for label, b in slips.items():
            if b != 0.0 and not SLIP_RANGE[0] <= b / R <= SLIP_RANGE[1]:
                raise ValidityError(self.name, f"{label} = {b:.3g} m = {b / R:.3g} R outside "
                                    f"[{SLIP_RANGE[0]:g}, {SLIP_RANGE[1]:g}] R", _instead(scene))
        if scene.kind == "sphere-sphere":
            q = scene.radius2 / R
            if not RADIUS_RATIO_RANGE[0] <= q <= RADIUS_RATIO_RANGE[1]:
                raise ValidityError(self.name, f"R2/R = {q:.4g} outside "
                                    f"[{RADIUS_RATIO_RANGE[0]:g}, {RADIUS_RATIO_RANGE[1]:g}]"
                                    + QUASI_STATIC, _instead(scene))
            deg = math.degrees(max(scene.contact_angle_sphere, scene.contact_angle_wall))
            if deg > PAIR_THETA_MAX + 1e-9:
                raise ValidityError(self.name, f"contact angle {deg:.4g}"
                                    f" deg > {PAIR_THETA_MAX:g} deg between spheres: the "
                                    "static bridge between equal spheres breaks its symmetry "
                                    "before its fold", _instead(scene))
        s = scene.gap_array / R
        if s.min() < MIN_GAP:
            raise ValidityError(self.name, f"S/R = {s.min():.3g} < {MIN_GAP:g}", _instead(scene))

    def check_options(self, scene: Scene, opts: dict[str, Any]) -> None:
        """A trajectory's motion replaces the scene's speed in the checks (its largest
        speed, with the direction of its motion)."""
        traj = opts.get("trajectory")
        if traj is not None:
            m = _Trajectory(self.name, traj, scene.radius,
                            scene.viscosity / scene.surface_tension * scene.radius)
            v = m.ca_max * scene.surface_tension / scene.viscosity
            scene = dataclasses.replace(scene, velocity=-v if m.separating else v)
        self.check(scene)

    def convergence_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Time steps and the force's error against a run at an eighth of the finest step
        (sphere-wall, V/R^3 = 1e-3, 20 deg, Ca = 1e-2 from S/R = 0.02 to t = 0.8 eta R/sigma,
        no remeshing)."""
        th = math.radians(20.0)
        wet = Wetting(th, th, 1e-3, 1e-3)

        def force(dt: float) -> float:
            r = run(1e-3, 0.02, 1e-2, wet, Stepping(dt=dt, t_end=0.8, remesh_shape=0.0,
                                                     remesh_curvature=0.05))
            return float(r.force[-1])

        dts = np.array([0.05, 0.025, 0.0125])
        ref = force(dts[-1] / 8)
        return dts, np.array([abs(force(dt) - ref) for dt in dts])

    def _force(self, scene: Scene, preset: str, gap_step: float = 5e-4,
               neck_step: float = 0.05, tolerance: float | None = None,
               default_slip: float = DEFAULT_SLIP,
               start: float | None = None, save_fields: str | None = None,
               checkpoint: str | None = None, line: str = "static",
               macro_length: float | None = None,
               trajectory: Mapping[str, Any] | None = None) -> ForceCurve:
        R, eta, sigma = scene.radius, scene.viscosity, scene.surface_tension
        gaps = scene.gap_array
        s = gaps / R
        sep = scene.velocity < 0  # v > 0 is approach
        motion = None
        if trajectory is not None:
            if start is not None:
                raise InputError(f"model '{self.name}': give start or trajectory, not both "
                                 "(a trajectory starts at its first gap)")
            motion = _Trajectory(self.name, trajectory, R, eta / sigma * R)
            sep, start = motion.separating, motion.s[0]
        if s.size > 1 and not np.all(np.diff(s) > 0 if sep else np.diff(s) < 0):
            raise InputError(f"model '{self.name}': gaps must {'increase' if sep else 'decrease'}"
                             f" when the surfaces {'separate' if sep else 'approach'} "
                             f"(velocity {scene.velocity:g} m/s); got {gaps.tolist()[:5]} m")
        if motion is not None and (s[-1] > motion.s[-1] if sep else s[-1] < motion.s[-1]):
            raise InputError(f"model '{self.name}': the last gap {gaps[-1]:.6g} m lies beyond "
                             f"the trajectory's last gap {motion.s[-1] * R:.6g} m")
        s0 = float(s[0]) if start is None else float(start)
        if not (math.isfinite(s0) and s0 >= MIN_GAP and (s0 <= s[0] if sep else s0 >= s[0])):
            raise InputError(f"model '{self.name}': start = {start!r} (S/R); allowed: >= "
                             f"{MIN_GAP:g} and {'at most' if sep else 'at least'} the first gap "
                             f"{s[0]:.6g}")
        for name, val, lo, hi in (("gap_step", gap_step, 1e-6, 0.1),
                                  ("neck_step", neck_step, 1e-3, 0.5),
                                  ("tolerance", 1e-6 if tolerance is None else tolerance,
                                   1e-9, 1e-2),
                                  ("default_slip", default_slip, *SLIP_RANGE)):
            if not (isinstance(val, int | float) and lo <= val <= hi):
                raise InputError(f"model '{self.name}': {name} = {val!r}; allowed: "
                                 f"[{lo:g}, {hi:g}]")
        pair = scene.kind == "sphere-sphere"
        q = scene.radius2 / R if pair else None  # R2/R
        half = pair and _symmetric(scene)
        scale = 2.0 if half else 1.0  # the half above the mid-plane: half gap, volume, speed
        vol = scene.bridge_volume / R**3
        ca = eta * abs(scene.velocity) / sigma
        if line not in LINE_LAWS:
            raise InputError(f"model '{self.name}': line = {line!r}; allowed: "
                             + ", ".join(LINE_LAWS))
        big = 1e3 * R
        if macro_length is not None and not (isinstance(macro_length, int | float)
                                             and 0 < macro_length <= big):
            raise InputError(f"model '{self.name}': macro_length = {macro_length!r} m; "
                             f"allowed: (0, {big:g}] m")
        wet = Wetting(scene.contact_angle_sphere, scene.contact_angle_wall,
                      scene.slip_length_sphere / R or default_slip,
                      scene.slip_length_wall / R or default_slip, line=line,
                      macro_length=1.0 if macro_length is None else macro_length / R)
        br = Bridge(radius=1.0, radius2=q,
                    contact_angle1=wet.theta_sphere, contact_angle2=wet.theta_wall,
                    surface_tension=1.0)
        s_fold = float(rupture_distance(br, vol))
        if s0 > s_fold:
            raise ValidityError(self.name, f"no static bridge at the start S/R = {s0:.6g} "
                                f"(beyond the static rupture distance {s_fold:.6g} R)",
                                _instead(scene))
        speed: float | Callable[[float], float] = (ca if sep else -ca) / scale
        if motion is not None:
            ca = motion.ca_max
            speed = motion.speed(scale)
        step = scaled_gap_step(gap_step, s_fold, ca)  # R, of the full gap
        files: list[tuple[float, str]] = []
        observer = None
        if save_fields is not None:
            observer = _FieldWriter(Path(save_fields), scene, s / scale, sep, scale, files)
        r = run(vol / scale, s0 / scale, speed, wet,
                Stepping(dt=step / ca, gap_end=float(s[-1]) / scale,
                         t_end=None if motion is None else motion.duration,
                         neck_stop=NECK_STOP if sep else 0.0, neck_step=neck_step,
                         tolerance=tolerance),
                MeshOptions(plane="symmetry" if half else "wall",
                            radius2=None if half else q),
                checkpoint=checkpoint, observer=observer,
                gap_at=None if motion is None else motion.gap(scale))
        pinched = sep and r.stopped == "neck"  # ("line", "solver": a line law's limit)
        if not pinched and r.stopped != "gap_end":
            raise SolverError(f"model '{self.name}': the run stopped at S/R = "
                              f"{r.gap[-1] * scale:.6g} before the last gap ({r.stopped}: "
                              f"{r.message})")
        curve = _curves(r, s, scale, pinched)
        total = curve["force"] * sigma * R
        cap = get_capillary(scene, preset)
        exists = curve["exists"]
        extras = {"neck_radius": curve["neck"] * R, "bridge_exists": exists}
        diag: dict[str, Any] = {
            "stopped": r.stopped, "message": r.message, "steps": r.steps,
            "remeshes": r.remeshes, "capillary_number": ca,
            "volume_error": float(np.abs(r.volume / r.volume[0] - 1.0).max()),
            "elements": r.diagnostics.get("elements", 0.0),
            "static_rupture_distance": s_fold * R}
        if pinched:
            p = locate_pinch(r)
            share = 0.5 if half else 1.0 - wall_fraction(r)
            extras["rupture_distance"] = np.full(s.size, p.gap * scale * R)
            extras["transfer_fraction"] = np.full(s.size, share)
            diag.update(pinch_slope=p.slope, pinch_spread=p.spread)
        if files:
            from wetcontact.fileio import safe_stem
            from wetcontact.meshes.io import write_pvd

            pvd = write_pvd(Path(save_fields) / f"stokes-dynamic-{safe_stem(scene.name)}.pvd",
                            [(g, Path(f)) for g, f in files])
            diag["files"] = [f for _, f in files] + [str(pvd)]
        cap = np.where(exists > 0, cap, 0.0)
        return ForceCurve(case=scene.name, model=self.name, gap=gaps,
                          force_viscous=np.where(exists > 0, total - cap, 0.0),
                          force_capillary=cap, extras=extras, diagnostics=diag)


def _symmetric(scene: Scene) -> bool:
    """Two equal spheres with equal angles and slip lengths: a bridge symmetric about its
    mid-plane (solved on its upper half)."""
    return (abs(scene.radius2 / scene.radius - 1.0) <= 1e-9
            and abs(scene.contact_angle_sphere - scene.contact_angle_wall) <= 1e-12
            and scene.slip_length_sphere == scene.slip_length_wall)


class _Trajectory:
    """A prescribed motion S(t) in the solver's units (time eta R / sigma, gap R)."""

    def __init__(self, model: str, data: Mapping[str, Any], R: float, t_unit: float) -> None:
        try:
            t = np.asarray(data["time"], dtype=float)
            g = np.asarray(data["gap"], dtype=float)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"model '{model}': trajectory needs numeric 'time' (s) and "
                             f"'gap' (m) sequences ({exc})") from None
        if t.ndim != 1 or t.shape != g.shape or t.size < 4 or not np.all(np.isfinite(t)) \
                or not np.all(np.isfinite(g)):
            raise InputError(f"model '{model}': trajectory 'time' and 'gap' must be finite "
                             f"1-D sequences of one length >= 4; got {t.shape} and {g.shape}")
        if not np.all(np.diff(t) > 0):
            raise InputError(f"model '{model}': trajectory 'time' must increase strictly")
        dg = np.diff(g)
        if not (np.all(dg > 0) or np.all(dg < 0)):
            raise InputError(f"model '{model}': trajectory 'gap' must be strictly monotone (a "
                             "separation or an approach; split a rebound at its turning point)")
        self.separating = bool(dg[0] > 0)
        self.tau = (t - t[0]) / t_unit
        self.s = g / R
        self.curve = PchipInterpolator(self.tau, self.s)
        rate = self.curve.derivative()(np.linspace(0.0, self.tau[-1], 2001))
        self.ca_max = float(np.max(np.abs(rate)))
        self.duration = float(self.tau[-1])
        if not CA_RANGE[0] <= self.ca_max <= CA_RANGE[1]:
            raise InputError(f"model '{model}': the trajectory's largest capillary number "
                             f"{self.ca_max:.3g} is outside [{CA_RANGE[0]:g}, {CA_RANGE[1]:g}]")

    def speed(self, scale: float) -> Callable[[float], float]:
        """dS/dt of the half-gap (``scale`` 2) or the gap (1), units sigma/eta."""
        d = self.curve.derivative()
        return lambda tau: float(d(min(tau, self.duration))) / scale

    def gap(self, scale: float) -> Callable[[float], float]:
        """S(t) of the half-gap (``scale`` 2) or the gap (1), units R."""
        return lambda tau: float(self.curve(min(tau, self.duration))) / scale


def get_capillary(scene: Scene, preset: str) -> np.ndarray:
    """The quasi-static capillary force (N) of ``meniscus`` at the scene's gaps (its
    ``preset``)."""
    from wetcontact.models import get_model

    return np.asarray(get_model("meniscus").force(scene, preset=preset).force_capillary)


def _curves(r: DynamicRun, s: np.ndarray, scale: float, pinched: bool) -> dict[str, np.ndarray]:
    """Force (sigma R), neck radius (R) and 1/0 for a bridge at the full gaps ``s`` (S/R)
    from the run's states (the half's gaps times ``scale``)."""
    g = r.gap * scale
    order = np.argsort(g)
    g, f, h = g[order], r.force[order], r.neck_radius[order]
    keep = np.r_[True, np.diff(g) > 1e-14]
    g, f, h = g[keep], f[keep], h[keep]
    if pinched:  # the force and the neck vanish at the pinch
        p = locate_pinch(r).gap * scale
        if p > g[-1]:
            g, f, h = np.r_[g, p], np.r_[f, 0.0], np.r_[h, 0.0]
    exists = (s <= g[-1] + 1e-12).astype(float)
    inside = np.clip(s, g[0], g[-1])
    if g.size >= 4:
        force, neck = CubicSpline(g, f)(inside), CubicSpline(g, h)(inside)
        if pinched:  # past the last state: linear to the pinch
            last = inside > r.gap.max() * scale
            force[last] = np.interp(inside[last], g, f)
            neck[last] = np.interp(inside[last], g, h)
    else:
        force, neck = np.interp(inside, g, f), np.interp(inside, g, h)
    return {"force": force * exists, "neck": np.maximum(neck, 0.0) * exists, "exists": exists}


class _FieldWriter:
    """Observer of a run: at the first state at or past each requested gap, the velocity
    (m/s) and pressure (Pa) at the mesh vertices to VTU (SI coordinates)."""

    def __init__(self, out: Path, scene: Scene, targets: np.ndarray, sep: bool, scale: float,
                 files: list[tuple[float, str]]) -> None:
        self.out, self.scene, self.targets, self.sep = out, scene, list(targets), sep
        self.scale, self.files = scale, files

    def __call__(self, t: float, dom: Domain, sol: StepSolution) -> None:
        from wetcontact.fileio import safe_stem
        from wetcontact.meshes.io import write_vtu

        while self.targets and ((dom.gap >= self.targets[0] - 1e-12) if self.sep
                                else (dom.gap <= self.targets[0] + 1e-12)):
            self.targets.pop(0)
            sc = self.scene
            R, u0 = sc.radius, sc.surface_tension / sc.viscosity
            nv = int(dom.mesh.t.max()) + 1
            vel = np.column_stack([sol.u[0:2 * nv:2], sol.u[1:2 * nv:2], np.zeros(nv)]) * u0
            gap_m = dom.gap * self.scale * R
            path = self.out / (f"stokes-dynamic-{safe_stem(sc.name)}-{len(self.files):03d}"
                               ".vtu")
            write_vtu(path, dom.mesh, {"velocity": vel,
                                       "pressure": sol.p[:nv] * sc.surface_tension / R},
                      scale=R)
            self.files.append((gap_m, str(path)))
