"""The registered ``calibrated-capillary`` model (:class:`CalibratedCapillary`): it checks
a scene against the closure's domain, evaluates
:func:`~wetcontact.reduced_models.calibrated_capillary.shipped.force_star` and bounds its error.

The error bound is the sampled bound tables' (:mod:`wetcontact.reduced_models.bounds`),
floored where they cannot be trusted to have found the worst
(:meth:`CalibratedCapillary.bound_floor`):

- the rupture window, within the held-out rupture error of S_c, where the closure's bridge
  may exist while the reference's does not, or the reverse (:data:`SPURIOUS`);
- with two angles, within :data:`RIDGE_ZONE_DEG` of the ridge, where the table is coarser:
  the held-out maxima of the zone's strata (:data:`RIDGE_STRATA`; the ridge's top within
  :data:`RIDGE_TOP_ZONE_DEG`, and at sphere angles of 17.5-35 deg where its jump appears);
- the ridge's window (:data:`RIDGE_WINDOW_DEG`, :func:`ridge_window_deg`): the jump of S_c
  sits where the true top is, the table's where its ridge series is, so that a point between
  the two is evaluated on the other side of the jump, its S_c off by up to
  :data:`RIDGE_JUMP_MAX`. The half-widths are four times the largest offset of the series
  from golden-section searches for the true top between its nodes.

Held-out maxima (rupture distance / force; goals 5e-4 / 1e-3): two angles on a wall
1.2e-5 / 2.0e-5 uniformly, 4.4e-5 / 4.0e-5 within :data:`RIDGE_ZONE_DEG` of the ridge,
2.0e-5 / 6.2e-5 within :data:`RIDGE_TOP_ZONE_DEG`, 2.2e-5 / 3.1e-4 where the jump appears,
1.5e-4 / 9.7e-4 within the ridge's window; two angles between spheres 2.5e-4 / 2.6e-4
uniformly, 7.6e-5 / 1.2e-4 near the ridge, 8.6e-5 / 1.1e-4 at its top, 3.8e-5 / 4.2e-4
where the jump appears, 3.8e-4 / 7.6e-4 within the ridge's window.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from wetcontact.errors import ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.reduced_models.bounds import estimate_or_none
from wetcontact.reduced_models.calibrated_capillary.coordinates import (
    ANGLE_TOL,
    PAIR_TWO_ANGLES,
    RATIO_RANGE,
    THETA_RANGE_DEG,
    TWO_ANGLE_TABLES,
    V_RANGE,
    WALL_TWO_ANGLES,
)
from wetcontact.reduced_models.calibrated_capillary.shipped import (
    _entry,
    force_star,
    ridge_deg,
    rupture_star,
)
from wetcontact.scene import Scene

RIDGE_ZONE_DEG = 3.0
"""Two angles on a wall: within this of the ridge the closure's bound is at least its
near-ridge held-out maximum (its stratum ``held_out_near_ridge``), whatever its sampled
bound table says (see the module's notes)."""
RIDGE_TOP_ZONE_DEG = 0.3
"""Two angles on a wall: within this of the ridge series lies the ridge's top (a jump of S_c
above the onset angle), the table's own held-out stratum ``held_out_ridge_top`` (and, at
sphere angles of 17.5-35 deg, ``held_out_ridge_onset`` and, at gaps to 0.999 S_c,
``held_out_ridge_onset_rupture``), see the module's notes."""
NEAR_RIDGE_MARGIN = 1.25
"""Factor on the near-ridge held-out maxima in :meth:`CalibratedCapillary.bound_floor`:
the bound tables' own margin (``wetcontact.generate.bounds.MARGIN``)."""
SPURIOUS = 1.0e3
"""The relative error claimed where the closure's force may exist while the reference's
does not (its rupture window, below its S_c): the bound tables' own
(``wetcontact.generate.bounds.SPURIOUS``)."""
RIDGE_WINDOW_DEG = {WALL_TWO_ANGLES: 5e-5, PAIR_TWO_ANGLES: 2e-3}
"""Per two-angle table, the half-width (deg) of the ridge's window: how far from the
table's ridge series the true ridge may lie, so that a point within it may be evaluated on
the wrong side of S_c's jump (above the onset angle); narrower in the sphere pairs' top
band (:data:`RIDGE_WINDOW_TOP`, :func:`ridge_window_deg`). Four times the largest offset of
the series from golden-section searches for the true top (to 1e-6 deg) between its nodes,
from the onset to 35 deg: on a wall (10 x 9 nodes) 1.3e-5 deg, between spheres (17 x 9 x 9
nodes in (w, a, b1)) 5.0e-4 deg between its a nodes near the onset, where the jump is below
1e-6 of S_c (``docs/calibrated_capillary.md``, The ridge's window)."""
RIDGE_WINDOW_TOP = {PAIR_TWO_ANGLES: (35.0, 4e-5)}
"""Per two-angle table, a (small) sphere angle (deg) and the ridge window's half-width
(deg) above it: between spheres, in the band from 35 to 70 deg (no onset within it; its
ridge series with 17 w nodes), the series is off by up to 9.6e-6 deg (63 golden-section
tops between its w, a and b1 nodes)."""


def ridge_window_deg(table: str, theta_sphere_deg: float) -> float:
    """The ridge window's half-width (deg) of the two-angle table ``table`` at the (small)
    sphere's angle (deg): :data:`RIDGE_WINDOW_DEG`, or :data:`RIDGE_WINDOW_TOP`'s above its
    angle."""
    top = RIDGE_WINDOW_TOP.get(table)
    if top is not None and theta_sphere_deg > top[0]:
        return top[1]
    return RIDGE_WINDOW_DEG[table]


RIDGE_JUMP_MAX = 1.2e-3
"""The largest jump of S_c at the ridge's top over the two-angle domain, relative: 1.15e-3
measured on a wall (V* = 0.1, theta_s = 44 deg), 9.2e-4 between spheres (r = 10, V* = 0.1,
theta1 = 44 deg), rounded up. Within :data:`RIDGE_WINDOW_DEG` of the ridge the rupture
distance may be off by this much."""
RIDGE_STRATA = {RIDGE_ZONE_DEG: ("held_out_near_ridge",),
                RIDGE_TOP_ZONE_DEG: ("held_out_near_ridge", "held_out_ridge_top",
                                     "held_out_ridge_onset", "held_out_ridge_onset_rupture")}
"""Per zone around the ridge (its half-width, deg), the held-out strata whose maxima floor
the closure's bound there (the narrowest zone that contains the point applies; a stratum
whose ``stratum`` names a ``theta_sphere_deg`` range only at sphere angles inside it:
``held_out_ridge_onset``, where the jump at the top appears, 17.5-35 deg)."""


@register
class CalibratedCapillary(Model):
    """Calibrated capillary closure: ``meniscus`` interpolated to about 1e-4 (held-out
    tables in the package data), one contact angle per pair or two."""

    name = "calibrated-capillary"
    component = "capillary"
    level = 0
    validity = ("pendular bridge on a wall or between spheres of radius ratio 1-10, "
                "V/R_small^3 in [1e-4, 0.1], one contact angle in [0, 70] deg on both "
                "solids, or two, each in [0, 70] deg, no gravity; any gap (0 beyond its "
                "rupture distance)")
    reference = "calibrated here: tensor Chebyshev interpolation of meniscus"
    source = ("fitted here: tensor Chebyshev interpolation of this package's meniscus solver "
              "(Young-Laplace; no published form)")
    cost = 1e-6
    presets = {"fast": {"precision": "mixed"}, "default": {"precision": "mixed"},
               "accurate": {"precision": "double"}}
    """``precision`` (:data:`PRECISIONS`): how the force's table (a tensor train with two
    angles, a low-rank sum with one) is summed; ``accurate`` sums every table in double
    precision (what the exported closures compute), the others the force's in single
    precision."""

    def check(self, scene: Scene) -> None:
        if scene.amount != "bridge":
            raise ValidityError(self.name, f"needs a liquid bridge (amount = 'bridge'), got "
                                f"amount = {scene.amount!r}",
                                "brenner" if scene.amount == "immersed" else "thinfilm")
        _entry(scene.kind)
        th1, th2 = scene.contact_angle_sphere, scene.contact_angle_wall
        if abs(th1 - th2) > ANGLE_TOL:
            _entry(TWO_ANGLE_TABLES[scene.kind])
        for th, what in ((th1, "sphere"), (th2, "wall" if scene.kind == "sphere-wall"
                                           else "sphere 2")):
            deg = math.degrees(th)
            if not THETA_RANGE_DEG[0] <= deg <= THETA_RANGE_DEG[1] * (1 + 1e-12):
                raise ValidityError(self.name, f"contact angle {deg:.4g} deg ({what}) outside "
                                    f"the calibrated [0, {THETA_RANGE_DEG[1]:g}] deg",
                                    "meniscus")
        if scene.gravity > 0 and scene.density > 0:
            raise ValidityError(self.name, "calibrated without gravity", "meniscus")
        v, ratio = self._v_ratio(scene)
        if not V_RANGE[0] * (1 - 1e-9) <= v <= V_RANGE[1] * (1 + 1e-9):
            raise ValidityError(self.name, f"V/R_small^3 = {v:.4g} outside the calibrated "
                                f"[{V_RANGE[0]:g}, {V_RANGE[1]:g}]", "meniscus")
        if ratio is not None and ratio > RATIO_RANGE[1] * (1 + 1e-9):
            raise ValidityError(self.name, f"radius ratio {ratio:.4g} outside the calibrated "
                                f"[1, {RATIO_RANGE[1]:g}]", "meniscus")

    @staticmethod
    def _v_ratio(scene: Scene) -> tuple[float, float | None]:
        assert scene.bridge_volume is not None
        if scene.kind == "sphere-wall":
            return scene.bridge_volume / scene.radius**3, None
        assert scene.radius2 is not None
        rs, rl = sorted((scene.radius, scene.radius2))
        return scene.bridge_volume / rs**3, rl / rs

    def small_radius(self, scene: Scene) -> float:
        """R_s: the sphere's radius on a wall, the smaller radius of a pair."""
        return scene.small_radius

    def rupture_distance(self, scene: Scene) -> float:
        """S_c (m)."""
        v, ratio = self._v_ratio(scene)
        th, other = self._angles(scene)
        return float(rupture_star(scene.kind, np.array(v), np.array(th),
                                  None if ratio is None else np.array(ratio),
                                  theta_wall=other)
                     * self.small_radius(scene))

    def ridge_distance(self, scene: Scene) -> float | None:
        """How far (deg) the other solid's angle lies from the two-angle table's ridge
        series (:func:`ridge_deg`) at the scene's volume, ratio and (small) sphere angle;
        ``None`` with one angle."""
        th_s, th_w = self._angles(scene)
        if th_w is None or abs(th_s - th_w) <= ANGLE_TOL:
            return None
        v, ratio = self._v_ratio(scene)
        return abs(math.degrees(th_w) - float(ridge_deg(v, math.degrees(th_s), ratio=ratio)))

    def ridge_window(self, scene: Scene) -> float | None:
        """The half-width (deg) of the ridge's window at the scene's (small) sphere angle
        (:func:`ridge_window_deg`); ``None`` with one angle."""
        th_s, th_w = self._angles(scene)
        if th_w is None:
            return None
        return ridge_window_deg(TWO_ANGLE_TABLES[scene.kind], math.degrees(th_s))

    def in_ridge_window(self, scene: Scene, dist: float | None = None) -> bool:
        """Whether the scene lies within its table's ridge window of the ridge
        (:meth:`ridge_window`), where the table may evaluate the other side of S_c's jump
        (at any sphere angle: below the onset angle, where the top is smooth, the window
        costs only bound); ``dist``: its :meth:`ridge_distance`, if known."""
        if dist is None:
            dist = self.ridge_distance(scene)
        return dist is not None and dist <= self.ridge_window(scene)

    def held_out_tables(self, scene: Scene
                        ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
        """The package data's held-out tables that describe ``scene``: the geometry's (its
        uniform one and its stress strata that hold the scene's sphere angle, e.g. nearly
        equal spheres, or near the ridge with two angles), and the ridge zone's: with two
        angles (a wall, or sphere pairs) within :data:`RIDGE_ZONE_DEG` of the ridge, the strata
        of the narrowest zone of :data:`RIDGE_STRATA` that contains it and hold its sphere
        angle (within :data:`RIDGE_TOP_ZONE_DEG`: the ridge's top, and at 17.5-35 deg where
        its jump appears; within :data:`RIDGE_WINDOW_DEG`: those and the table's
        ``held_out_ridge_window``); empty elsewhere."""
        th_s, _ = self._angles(scene)
        dist = self.ridge_distance(scene)
        two = dist is not None
        e = _entry(TWO_ANGLE_TABLES[scene.kind] if two else scene.kind)
        ts = math.degrees(th_s)

        def applies(k: str) -> bool:  # a stratum of some sphere angles only
            if k not in e:
                return False
            lo, hi = e[k].get("stratum", {}).get("theta_sphere_deg", THETA_RANGE_DEG)
            return lo <= ts <= hi

        geometry = [e["held_out"], *(e[k] for k in sorted(e)
                                     if k.startswith("held_out_") and applies(k))]
        if dist is None:
            return geometry, []
        zones = [z for z in RIDGE_STRATA if dist <= z]
        if not zones:
            return geometry, []
        names = RIDGE_STRATA[min(zones)] + (("held_out_ridge_window",)
                                            if self.in_ridge_window(scene, dist) else ())
        return geometry, [e[k] for k in names if k in e and applies(k)]

    def rupture_window(self, scene: Scene) -> float:
        """``w``, the rupture window's half-width over S_c (:meth:`bound_floor`): the
        largest held-out error of the rupture distance among the tables that describe the
        scene (:meth:`held_out_tables`), at least :data:`RIDGE_JUMP_MAX` within the ridge's
        window, times :data:`NEAR_RIDGE_MARGIN`."""
        geometry, ridge = self.held_out_tables(scene)
        return NEAR_RIDGE_MARGIN * max(
            [ho["rupture_distance"]["max"] for ho in geometry + ridge]
            + ([RIDGE_JUMP_MAX] if self.in_ridge_window(scene) else []))

    def bound_floor(self, scene: Scene, rupture_distance: float | None = None
                    ) -> np.ndarray:
        """Smallest error bound this closure may claim at each of the scene's gaps, where
        its sampled bound tables cannot be trusted to have found its worst (0 elsewhere).

        - Its **rupture window**: within ``w S_c`` of its own rupture distance, ``w`` the
          held-out maximum of the rupture distance's error (:meth:`held_out_tables`) times
          :data:`NEAR_RIDGE_MARGIN` (:meth:`rupture_window`), the bridge may or may not
          exist: below S_c the closure's force may be spurious (:data:`SPURIOUS`), above
          it the closure's 0 may miss a force (relative error 1, times the margin).
        - With two angles (a wall or sphere pairs) within :data:`RIDGE_ZONE_DEG` of the
          ridge, where the table is coarser: at the gaps below the window, the largest
          held-out force error of the zone's strata among points where the closure's
          bridge exists
          (``force_attached``), and its rupture distance's maximum, times the margin.
        - Within :data:`RIDGE_WINDOW_DEG` of the ridge, where the table may evaluate the
          other side of S_c's jump, ``w`` is at least :data:`RIDGE_JUMP_MAX` times the
          margin.
        """
        gap = scene.gap_array
        sc = self.rupture_distance(scene) if rupture_distance is None else rupture_distance
        _, ridge = self.held_out_tables(scene)
        w = self.rupture_window(scene)
        out = np.zeros(gap.shape)
        if ridge:
            out[:] = NEAR_RIDGE_MARGIN * max(
                max(ho.get("force_attached", ho["force"])["max"], ho["rupture_distance"]["max"])
                for ho in ridge)
        out[(gap >= sc * (1.0 - w)) & (gap < sc)] = SPURIOUS
        out[(gap >= sc) & (gap <= sc * (1.0 + w))] = NEAR_RIDGE_MARGIN
        return out

    @staticmethod
    def _angles(scene: Scene) -> tuple[float, float | None]:
        """The (small) sphere's angle and the other solid's (rad): on a wall the sphere's
        and the wall's; for a sphere pair the smaller sphere's (sphere 1's at equal radii)
        and the larger one's, or ``None`` when the two are one angle."""
        th1, th2 = scene.contact_angle_sphere, scene.contact_angle_wall
        if scene.kind == "sphere-wall":
            return th1, th2
        if abs(th1 - th2) <= ANGLE_TOL:
            return th1, None
        assert scene.radius2 is not None
        return (th2, th1) if scene.radius2 < scene.radius else (th1, th2)

    def _force(self, scene: Scene, preset: str, precision: str = "mixed", **opts: Any
               ) -> ForceCurve:
        rs = self.small_radius(scene)
        v, ratio = self._v_ratio(scene)
        gap = scene.gap_array
        th, other = self._angles(scene)
        f, s_c = force_star(scene.kind, v, th, gap / rs, ratio, theta_wall=other,
                            precision=precision)
        sc = float(s_c.flat[0]) * rs
        force = 2.0 * np.pi * scene.surface_tension * rs * f
        est = estimate_or_none(self.name, "capillary", scene, sc)
        if est is not None:
            est = np.maximum(est, self.bound_floor(scene, sc))
        diag = {}
        dist = self.ridge_distance(scene)
        if self.in_ridge_window(scene, dist):
            window = self.ridge_window(scene)
            diag["ridge_window"] = (
                f"the other solid's angle is {dist:.3g} deg from the table's ridge series, "
                f"within its error ({window:g} deg): the table may evaluate the other side "
                f"of S_c's jump, so S_c may be off by up to {RIDGE_JUMP_MAX:g} and the force "
                "near rupture spurious or missing; the error bound says so (meniscus "
                "resolves it)")
        return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=None,
                          force_capillary=-force,
                          extras={"rupture_distance": np.full(gap.shape, sc)},
                          error_estimate=est, diagnostics=diag)
