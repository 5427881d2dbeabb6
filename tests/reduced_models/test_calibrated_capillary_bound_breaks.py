"""calibrated-capillary's measured bound where it broke (issue 58), and around there.

Two points where the closure erred by more than the bound it reported, and ``solve --tol``
chose it: equal spheres at the top of the angle range at a small gap (the bin 55-70 deg,
S/S_c below 0.1 claimed 7.4e-5, the error 1.1e-4), and unequal spheres with two low angles
just below 0.999 S_c (the bin 0.99-0.999 S_c below 20 deg claimed 7.7e-5, the error
2.5e-4). The bound tables now measure the top-angle stratum
(``generate.bounds.PAIR_TOP_ANGLE``) and every bin's upper edge toward rupture
(``generate.bounds.CC_EDGE_X``).

Four more, found by the seeded scan ``benchmarks/scan_cc_bound_breaks.py`` (seed 58, 60
scenes a region) with two angles, where the bins had been measured by one-angle scenes and
few two-angle ones: sphere pairs with both angles in 55-70 deg (at a middle gap, and at
0.9995 S_c), and low angles 3-8 deg from the two-angle table's ridge, just outside the zone
where the closure floors its bound (a sphere pair and a wall). The bound tables now measure
both (``generate.bounds.PAIR_TWO_TOP_ANGLES``, ``generate.bounds.LOW_OFF_RIDGE``).

Checked here: the closure's error against ``meniscus`` (the bounds' reference, default
preset; at the points also against the shooting solution of ``tests/solver/shooting.py``)
is at most the bound the closure reports, at the points and at seeded points within 2 % of
each in every coordinate (clipped to the domain); and ``--tol`` at a tolerance between the
former bound and the error no longer chooses the closure there.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

from wetcontact import select
from wetcontact.cli import main
from wetcontact.generate.bounds import make_scene, rel_error
from wetcontact.models import get_model
from wetcontact.scene import Scene

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "solver"))
from shooting import shoot_volume  # noqa: E402

R = 1.0e-3
THETA_MAX_DEG = 70.0
RATIO_MAX = 10.0



class Break(NamedTuple):
    """A point where the closure's error exceeded the bound it reported."""

    kind: str
    r2: float | None
    """Radius of sphere 2 (m); ``None`` on a wall."""
    v: float
    """Bridge volume (m^3)."""
    angles: tuple[float, float]
    """Sphere 1's angle and sphere 2's or the wall's (deg)."""
    s: float
    """Gap (m)."""
    tol: float
    """A ``--tol`` between the former bound and the error: the closure was chosen."""
    found: float
    """The error found (relative, against ``meniscus``)."""


BREAKS = {
    "equal-spheres-top-angle-small-gap": Break(
        "sphere-sphere", R, 0.05958105485436923 * R**3,
        (69.46324486752634, 69.46324486752634), 0.008042799573207164 * R, 1e-4, 1.14e-4),
    "unequal-spheres-near-rupture": Break(
        "sphere-sphere", 2.603985477502474e-3, 5.017797819176478e-13,
        (18.934162381770328, 16.797533183253105), 8.69624946414701e-5, 2e-4, 2.47e-4),
    # the seeded scan (benchmarks/scan_cc_bound_breaks.py, seed 58): region, scene; S/S_c;
    # the bound then
    "pair-two-top-angles-middle-gap": Break(  # top #16; 0.25 S_c; 3.52e-5
        "sphere-sphere", 2.8773961880542394e-3, 0.0001372265097906068 * R**3,
        (69.32526274271967, 55.72087267457304), 0.25 * 5.908111994871594e-05, 3.6e-5,
        3.79e-5),
    "pair-two-top-angles-near-rupture": Break(  # top #40; 0.9995 S_c; 3.43e-3
        "sphere-sphere", 1.5634725652811838e-3, 0.0012314507482603248 * R**3,
        (62.34098978678297, 69.83412994311901), 0.9995 * 0.00013683035716160533, 5e-3,
        7.45e-3),
    "pair-low-angles-off-ridge": Break(  # low-pair #35; 0.75 S_c; 8.89e-6
        "sphere-sphere", 5.912166594775047e-3, 0.0002855772269225273 * R**3,
        (2.3771104392212505, 19.575507405379298), 0.75 * 6.765611059025077e-05, 2e-5,
        2.34e-5),
    # low-wall #32; 0.9 S_c; 5.05e-6. The error of this gap alone: among the scan's gaps
    # 1.28e-5, since the force's table is summed in single precision, in another order for
    # one gap than for several (1.10e-5 in double precision)
    "wall-low-angles-off-ridge": Break(
        "sphere-wall", None, 0.0003021008683202938 * R**3,
        (9.928164877278574, 12.817221700830045), 0.9 * 7.114321568133513e-05, 8e-6,
        9.89e-6),
}
FORMER_BOUND = {"pair-two-top-angles-middle-gap": 3.52e-5,
                "pair-two-top-angles-near-rupture": 3.43e-3,
                "pair-low-angles-off-ridge": 8.89e-6, "wall-low-angles-off-ridge": 5.05e-6}
"""The bound the closure reported at the seeded scan's breaks before the strata that
measure there."""


def _scene(kind: str, r2: float | None, v: float, angles: tuple[float, float],
           s: float | np.ndarray) -> Scene:
    return make_scene(kind, {"bridge_volume": v}, np.atleast_1d(s), r2, angles)


def _error_and_bound(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The closure's relative error against ``meniscus`` (default preset) at the scene's
    gaps, and the bound it reports there."""
    curve = get_model("calibrated-capillary").force(scene)
    ref = get_model("meniscus").force(scene).force_capillary
    assert curve.error_estimate is not None
    return rel_error(curve.force_capillary, ref), np.asarray(curve.error_estimate)


@pytest.mark.parametrize("name", list(BREAKS))
def test_bound_holds_where_it_broke(name: str) -> None:
    """At the point the closure still errs by what the issue found (its table is unchanged),
    more than the tolerance; the meniscus reference agrees with the shooting solution, and
    the bound the closure reports now covers its error."""
    kind, r2, v, angles, s, tol, found = BREAKS[name]
    scene = _scene(kind, r2, v, angles, s)
    men = get_model("meniscus").force(scene, preset="accurate")
    shot = shoot_volume(v / R**3, s / R, math.radians(angles[0]), math.radians(angles[1]),
                        None if r2 is None else r2 / R,
                        (float(men.extras["filling_angle"][0]),
                                 float(men.extras["laplace_pressure"][0]) * R / 0.072))
    assert shot.residual < 1e-10, "shooting did not converge"
    shooting_force = -shot.force * 0.072 * R
    assert abs(men.force_capillary[0] / shooting_force - 1.0) < 1e-7
    err, bound = (float(a[0]) for a in _error_and_bound(scene))
    closure = get_model("calibrated-capillary").force(scene).force_capillary[0]
    assert abs(closure / shooting_force - 1.0) == pytest.approx(err, rel=1e-2)
    assert err == pytest.approx(found, rel=0.02) and err > tol
    assert bound >= err, (err, bound)


@pytest.mark.parametrize("name", list(BREAKS))
def test_tol_no_longer_chooses_the_closure_there(name: str) -> None:
    """``select.choose`` (what ``solve --tol`` runs) at the issue's tolerance: the closure's
    bound exceeds it, so another model meets it."""
    kind, r2, v, angles, s, tol, _ = BREAKS[name]
    sel = select.choose(_scene(kind, r2, v, angles, s), tol)
    choice = sel.choices["capillary"]
    assert choice.model.name != "calibrated-capillary" and choice.met
    got = select.component_bound(get_model("calibrated-capillary"), "default", "capillary",
                                 _scene(kind, r2, v, angles, s))
    assert not isinstance(got, str) and float(got[0].max()) > tol


@pytest.mark.parametrize("name", ["equal-spheres-top-angle-small-gap",
                                  "wall-low-angles-off-ridge"])
def test_solve_tol_on_the_command_line(name: str, tmp_path, capsys) -> None:
    """``wetcontact solve CASE --tol TOL`` at the point: a model other than the closure,
    within the tolerance of the reference."""
    kind, r2, v, angles, s, tol, _ = BREAKS[name]
    geometry = f'kind = "{kind}"\nradius = {R!r}\n' + (
        "" if r2 is None else f"radius2 = {r2!r}\n")
    other = "contact_angle_wall" if kind == "sphere-wall" else "contact_angle_sphere2"
    case = tmp_path / "break.toml"
    case.write_text(
        f'name = "break"\n[geometry]\n{geometry}[liquid]\nviscosity = 1e-3\n'
        f'surface_tension = 0.072\ndensity = 998.0\ncontact_angle_sphere = {angles[0]!r}\n'
        f'{other} = {angles[1]!r}\n[amount]\nbridge_volume = {v!r}\n'
        f'[motion]\nvelocity = 0.1\ngaps = [{s!r}]\n')
    assert main(["solve", str(case), "--tol", f"{tol:g}", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model_capillary"] != "calibrated-capillary"
    assert max(out["error_estimate_capillary"]) <= tol
    ref = get_model("meniscus").force(_scene(kind, r2, v, angles, s)).force_capillary[0]
    assert abs(out["force_capillary"][0] / ref - 1.0) <= tol


def _neighbourhood(name: str, n: int = 30, gaps: int = 8, rel: float = 0.02, seed: int = 58
                   ) -> list[tuple[str, float | None, float, tuple[float, float], np.ndarray]]:
    """``n`` seeded scenes within ``rel`` of the point in each coordinate (the radius of
    sphere 2, the volume, each angle; equal spheres stay equal, with one angle), each at
    ``gaps`` seeded gaps within ``rel`` of the point's, clipped to the closure's domain
    (angles to 70 deg, the radius ratio to 10)."""
    kind, r2, v, angles, s, _, _ = BREAKS[name]
    rng = np.random.default_rng(seed)
    equal = r2 == R and angles[0] == angles[1]
    out = []
    for _ in range(n):
        f = 1.0 + rng.uniform(-rel, rel, 4)
        th1 = min(angles[0] * f[2], THETA_MAX_DEG)
        th2 = th1 if equal else min(angles[1] * f[3], THETA_MAX_DEG)
        r2_k = (None if r2 is None else R if equal
                else min(max(r2 * f[0], R), RATIO_MAX * R))
        out.append((kind, r2_k, v * f[1], (th1, th2),
                    np.sort(s * (1.0 + rng.uniform(-rel, rel, gaps)))))
    return out


def _check_neighbourhood(name: str, n: int = 30) -> float:
    """Every gap of every scene of :func:`_neighbourhood` (``n`` of them): error <= bound;
    the largest error found."""
    worst = 0.0
    for kind, r2, v, angles, s in _neighbourhood(name, n):
        err, bound = _error_and_bound(_scene(kind, r2, v, angles, s))
        assert np.all(err <= bound), (name, r2, v, angles, s, err, bound)
        worst = max(worst, float(err.max()))
    return worst


def test_bound_holds_around_the_unequal_spheres_near_rupture() -> None:
    """30 seeded scenes around the unequal pair, 8 gaps each (S from 0.98 to 1.02 of 0.999
    S_c: past the closure's or the reference's rupture too), about 17 s. Against the former
    bound table 16 of the 240 gaps were above their bound (up to 2.0e-4 at 0.9988 S_c, bound
    7.7e-5); now the largest error over bound is 0.76 (3.4e-5 at 0.985 S_c)."""
    assert _check_neighbourhood("unequal-spheres-near-rupture") > 1e-4


@pytest.mark.slow
def test_bound_holds_around_the_equal_spheres_at_the_top_angle() -> None:
    """30 seeded scenes around the equal spheres at 69.5 deg, 8 gaps each (angles clipped to
    70 deg, where the error is largest), about 60 s. Against the former bound table 208 of
    the 240 gaps were above their bound 7.4e-5 (up to 1.7e-4); now the largest error over
    bound is 0.44 (bound 3.8e-4)."""
    assert _check_neighbourhood("equal-spheres-top-angle-small-gap") > 1e-4


WALL_OFF_RIDGE_OPEN = pytest.mark.xfail(
    strict=True, reason="open: a neighbour (V* = 3.05e-4, 9.86 deg on the sphere) errs by "
    "1.704e-5 just below 0.9 S_c against the remeasured bound 1.683e-5 of the bin 0-20 deg, "
    "0.8-0.9 S_c (5.05e-6 before); the stratum LOW_OFF_RIDGE's 60 walls found 1.35e-5 there")


@WALL_OFF_RIDGE_OPEN
def test_bound_holds_around_the_wall_with_low_angles_off_the_ridge() -> None:
    """20 seeded scenes around the wall at 9.9/12.8 deg, 5.0 deg from the two-angle table's
    ridge, 8 gaps each (S within 2 % of 0.9 S_c). The former bound there was 5.05e-6 (the
    bin 0-20 deg, 0.8-0.9 S_c) and 0.9 S_c erred by 1.28e-5 among the scan's gaps."""
    assert _check_neighbourhood("wall-low-angles-off-ridge", n=20) > FORMER_BOUND[
        "wall-low-angles-off-ridge"]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["pair-two-top-angles-middle-gap",
                                  "pair-two-top-angles-near-rupture",
                                  "pair-low-angles-off-ridge",
                                  pytest.param("wall-low-angles-off-ridge",
                                               marks=WALL_OFF_RIDGE_OPEN)])
def test_bound_holds_around_the_scans_breaks(name: str) -> None:
    """30 seeded scenes around each break of the seeded scan, 8 gaps each (S within 2 % of
    the point's: at 0.9995 S_c past the closure's or the reference's rupture too), each
    about 30-40 s: every error at most the bound, and the largest above the former bound
    (:data:`FORMER_BOUND`)."""
    assert _check_neighbourhood(name) > FORMER_BOUND[name]
