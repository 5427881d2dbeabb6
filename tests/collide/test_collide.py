"""Collisions against analytic limits, energy conservation and Hertz's contact time."""

from __future__ import annotations

import copy
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from wetcontact.collide import ORDER, collide, collision_case_from_dict
from wetcontact.collide.contact import HERTZ_TIME, Thornton
from wetcontact.errors import CaseError

R, ETA, V0 = 1e-3, 1e-3, 0.1
X0, XR = 1e-4, 1e-6


def case_dict(st: float = 100.0, e_dry: float = 0.9, **tables: dict) -> dict:
    """A sphere-wall impact whose Stokes number St = m v0/(6 pi eta R^2) is ``st``."""
    m = st * 6 * math.pi * ETA * R * R / V0
    d = {"name": "impact", "geometry": {"kind": "sphere-wall", "radius": R},
         "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 1000.0},
         "amount": {"immersed": True},
         "impact": {"velocity": V0, "start_gap": X0},
         "solid": {"density": m / (4 / 3 * math.pi * R ** 3), "restitution": e_dry,
                   "roughness": XR}}
    for k, v in tables.items():
        d[k] = {**d.get(k, {}), **v}
    return d


def run(d: dict, **kw):
    return collide(collision_case_from_dict(copy.deepcopy(d)), **kw)


@pytest.mark.parametrize("st", [10.0, 31.6, 100.0, 316.0, 1000.0])
@pytest.mark.parametrize("rebound_resistance", [False, True])
def test_rigid_lubrication_limit(st: float, rebound_resistance: bool) -> None:
    """Davis, Serayssol & Hinch 1986: e = e_dry (1 - L/St) with cavitation on rebound,
    e = e_dry - (1 + e_dry) L/St with the same force on rebound; L = ln(x0/x_r)."""
    d = case_dict(st, phases={"viscous_on_rebound": rebound_resistance})
    res = run(d, viscous="reynolds", capillary="none")
    lg = math.log(X0 / XR)
    exact = 0.9 - 1.9 * lg / st if rebound_resistance else 0.9 * (1 - lg / st)
    assert res.outcome == "rebound"
    assert abs(res.restitution - exact) < 1e-6
    assert abs(res.contact_velocity - V0 * (1 - lg / st)) < 1e-6 * V0
    assert abs(res.diagnostics["energy_residual"]) < 1e-9


@pytest.mark.parametrize("rebound_resistance", [False, True])
def test_stick_below_critical_stokes(rebound_resistance: bool) -> None:
    lg = math.log(X0 / XR)
    st_crit = (1 + 1 / 0.9) * lg if rebound_resistance else lg
    d = case_dict(0.95 * st_crit, phases={"viscous_on_rebound": rebound_resistance})
    res = run(d, viscous="reynolds", capillary="none")
    assert res.outcome == "stick" and res.restitution == 0.0
    above = run(case_dict(1.05 * st_crit, phases={"viscous_on_rebound": rebound_resistance}),
                viscous="reynolds", capillary="none")
    assert above.outcome == "rebound" and above.restitution > 0.0
    assert abs(res.diagnostics["energy_residual"]) < 1e-9


@pytest.mark.parametrize("st", [10.0, 100.0, 1000.0])
def test_finite_film_limit(st: float) -> None:
    """Pitois' factor (1 - x/delta)^2: L = ln(delta/x_r) - 2(1 - x_r/delta)
    + (1 - x_r^2/delta^2)/2, derived by integrating m dv = -6 pi eta R^2 (1 - x/d)^2 dx/x."""
    delta = X0
    d = case_dict(st, amount={"film_thickness": delta}, phases={"viscous_on_rebound": False})
    d["amount"] = {"film_thickness": delta}
    res = run(d, viscous="reynolds-finite", capillary="none")
    lg = math.log(delta / XR) - 2 * (1 - XR / delta) + (1 - (XR / delta) ** 2) / 2
    assert abs(res.restitution - 0.9 * (1 - lg / st)) < 1e-6
    assert max(res.diagnostics["interpolation_error"].values()) < 1e-8
    assert [p.name for p in res.phases][:3] == ["penetration", "contact", "emergence"]


def test_no_dissipation_gives_one() -> None:
    res = run(case_dict(50.0, e_dry=1.0), viscous="none", capillary="none")
    assert abs(res.restitution - 1.0) < 1e-9
    assert res.models["viscous"] is None and res.models["capillary"] is None
    assert abs(res.energy["impact"] - res.energy["rebound"]) < 1e-9 * res.energy["impact"]


def hertz_dict(e_dry: float, model: str = "hertz") -> dict:
    d = case_dict(100.0, e_dry=e_dry, contact={"model": model})
    d["solid"].update(density=2500.0, youngs_modulus=7e10, poisson_ratio=0.25)
    d["impact"]["velocity"] = 0.5
    return d


def test_hertz_contact_time() -> None:
    """t_c = 2.86827 (m*^2 / (R* E*^2 v))^(1/5) for an undamped dry impact."""
    assert abs(HERTZ_TIME - 2.86827) < 1e-5
    res = run(hertz_dict(1.0), viscous="none", capillary="none")
    (contact,) = [p for p in res.phases if p.name == "contact"]
    m = 2500.0 * 4 / 3 * math.pi * R ** 3
    e_star = 1 / (2 * (1 - 0.25 ** 2) / 7e10)
    t_c = 2.86827 * (m * m / (R * e_star ** 2 * 0.5)) ** 0.2
    assert abs((contact.end - contact.start) / t_c - 1) < 1e-4
    assert abs(res.restitution - 1) < 1e-9


@pytest.mark.parametrize("model", ["hertz", "thornton"])
@pytest.mark.parametrize("e_dry", [0.3, 0.8])
def test_damped_contacts_give_e_dry(model: str, e_dry: float) -> None:
    res = run(hertz_dict(e_dry, model), viscous="none", capillary="none")
    assert abs(res.restitution - e_dry) < 1e-7
    assert abs(res.diagnostics["energy_residual"]) < 1e-9


def test_thornton_against_closed_form() -> None:
    """Thornton 1997, eq. for the restitution of elastic-perfectly plastic spheres:
    e = (6 sqrt(3)/5)^(1/2) (1 - (v_y/v)^2/6)^(1/2)
        ((v_y/v) / ((v_y/v) + 2 (6/5 - (v_y/v)^2/5)^(1/2)))^(1/4)."""
    e_star, r, m, p_y = 4e10, 1e-3, 1e-5, 1e9
    th = Thornton(e_star, r, p_y)
    v_y = math.sqrt(16 / 15 * (math.pi / 2) ** 5 * p_y ** 5 * r ** 3 / (e_star ** 4 * m))
    for ratio in (0.05, 0.2, 0.5):
        q = ratio
        closed = math.sqrt(6 * math.sqrt(3) / 5) * math.sqrt(1 - q * q / 6) * (
            q / (q + 2 * math.sqrt(6 / 5 - q * q / 5))) ** 0.25
        assert abs(th.dry_restitution(m, v_y / q) - closed) < 2e-3


def test_integrator_order() -> None:
    """DOP853 at fixed steps, the contact located on its dense output: the contact
    speed's error falls as h^ORDER (7). A roughness of x0/10 keeps the force smooth on the
    scale of the steps (1/12 to 1/24 of the penetration time)."""
    d = case_dict(30.0, phases={"viscous_on_rebound": False}, solid={"roughness": X0 / 10})
    exact = V0 * (1 - math.log(10.0) / 30.0)
    t_pen = run(d, viscous="reynolds", capillary="none").phases[0].end
    hs = t_pen / np.array([12.0, 16.0, 24.0])
    err = [abs(run(d, viscous="reynolds", capillary="none", max_step=h, fixed_step=True)
               .contact_velocity - exact) for h in hs]
    from wetcontact.models import observed_order

    assert abs(observed_order(hs, err) - ORDER) < 0.75


def test_sphere_pair_uses_reduced_mass_and_radius() -> None:
    d = case_dict(100.0, phases={"viscous_on_rebound": False})
    d["geometry"] = {"kind": "sphere-sphere", "radius": R, "radius2": 3 * R}
    res = run(d, viscous="reynolds", capillary="none")
    m1 = d["solid"]["density"] * 4 / 3 * math.pi * R ** 3
    m_star = m1 * 27 / 28
    st = m_star * V0 / (6 * math.pi * ETA * (0.75 * R) ** 2)
    assert abs(res.stokes_number / st - 1) < 1e-12
    assert abs(res.restitution - 0.9 * (1 - math.log(X0 / XR) / st)) < 1e-6


@pytest.mark.parametrize("mu", [0.05, 1.0])
def test_oblique_coulomb_impulse(mu: float) -> None:
    """Eqs. 1.5-1.6: sliding changes u_t by mu J_n / m; sticking ends with a rolling
    contact point, u_t = (5/7) u_t0 for a sphere without spin."""
    d = case_dict(100.0, e_dry=0.8, impact={"tangential_velocity": 0.05},
                  solid={"friction": mu})
    res = run(d, viscous="none", capillary="none")
    ut = res.trajectory["tangential_velocity"][-1]
    if mu < 0.1:
        assert abs(ut - (0.05 - mu * 1.8 * V0)) < 1e-12
    else:
        assert abs(ut - 5 / 7 * 0.05) < 1e-12 and abs(res.tangential_restitution) < 1e-12
    assert abs(res.diagnostics["energy_residual"]) < 1e-9
    assert res.rebound_angle == pytest.approx(math.degrees(math.atan2(ut, 0.8 * V0)))


def test_film_with_bridge_closes_energy_budget() -> None:
    d = case_dict(300.0, amount={"film_thickness": X0})
    d["amount"] = {"film_thickness": X0}
    d["liquid"]["contact_angle"] = 20.0
    res = run(d)
    assert res.models["capillary"] == "calibrated-capillary"
    assert [p.name for p in res.phases] == ["penetration", "contact", "emergence", "bridge"]
    assert res.energy["capillary"] < 0.0 < res.energy["bridge"]  # pulls in, holds back
    assert abs(res.diagnostics["energy_residual"]) < 1e-9
    # the force tables' interpolation error moves e by less than 1e-6
    assert 0.0 < res.diagnostics["restitution_interpolation_bound"] < 1e-6
    # the liquid each body carries away: the meniscus's division of the critical bridge
    liq = res.liquid
    assert liq["transfer_source"].startswith("meniscus")
    assert 0.0 < liq["transfer_fraction"] < 0.5  # a sphere on a wall keeps less than half
    assert abs(liq["body1"] + liq["body2"] - liq["bridge_volume"]) <= 1e-12 * liq["body2"]


@pytest.mark.parametrize("edit, field", [
    (lambda d: d.pop("impact"), "[impact]"),
    (lambda d: d.pop("solid"), "[solid]"),
    (lambda d: d["solid"].update(restitution=1.5), "solid.restitution"),
    (lambda d: d["solid"].update(restitution=0.0), "solid.restitution"),
    (lambda d: d["solid"].update(roughness=-1e-6), "solid.roughness"),
    (lambda d: d["impact"].update(start_gap=0.5 * XR), "impact.start_gap"),
    (lambda d: d["contact"].update(model="elastic"), "contact.model"),
    (lambda d: d["contact"].update(model="hertz"), "solid.youngs_modulus"),
])
def test_bad_input_names_the_field(edit, field: str) -> None:
    d = case_dict(100.0, contact={})
    edit(d)
    with pytest.raises(CaseError, match=field.replace("[", r"\[").replace("]", r"\]")):
        collision_case_from_dict(d, source="case.toml")


def toml(d: dict) -> str:
    out = []
    for k, v in d.items():
        if not isinstance(v, dict):
            out.append(f"{k} = {json.dumps(v)}")
    for k, v in d.items():
        if isinstance(v, dict):
            out.append(f"[{k}]")
            out += [f"{kk} = {json.dumps(vv) if not isinstance(vv, bool) else str(vv).lower()}"
                    for kk, vv in v.items()]
    return "\n".join(out) + "\n"


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wetcontact", *args], capture_output=True,
                          text=True, timeout=120)


def test_cli_json_and_trajectory(tmp_path) -> None:
    path = tmp_path / "impact.toml"
    path.write_text(toml(case_dict(100.0)))
    traj = tmp_path / "t.csv"
    p = cli("collide", str(path), "--viscous", "reynolds", "--capillary", "none", "--json",
            "--trajectory", str(traj))
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    for key in ("restitution", "outcome", "contact_velocity", "rebound_velocity", "phases",
                "energy", "models", "settings", "provenance"):
        assert key in out
    assert out["models"]["viscous"] == "reynolds"
    rows = traj.read_text().splitlines()
    assert rows[0].startswith("time (s),gap (m),velocity (m/s)") and len(rows) > 10


@pytest.mark.parametrize("edit, field", [
    (lambda d: d.pop("impact"), "[impact]"),
    (lambda d: d["solid"].update(restitution=2.0), "solid.restitution"),
])
def test_cli_bad_input_one_line(tmp_path, edit, field: str) -> None:
    d = case_dict(100.0)
    edit(d)
    path = tmp_path / "bad.toml"
    path.write_text(toml(d))
    p = cli("collide", str(path))
    assert p.returncode == 2
    assert len(p.stderr.strip().splitlines()) == 1 and field in p.stderr


def test_shipped_collision_cases_run() -> None:
    from pathlib import Path

    from wetcontact.collide import load_collision_case

    files = sorted((Path(__file__).parents[2] / "cases" / "collisions").glob("*.toml"))
    assert files
    for f in files:
        res = collide(load_collision_case(f), trajectory=False)
        assert res.outcome in ("rebound", "stick")
        assert abs(res.diagnostics["energy_residual"]) < 1e-9


def test_cli_bad_trajectory_path_before_any_work(tmp_path) -> None:
    path = tmp_path / "impact.toml"
    path.write_text(toml(case_dict(100.0)))
    p = cli("collide", str(path), "--trajectory", str(tmp_path / "no" / "such" / "t.csv"))
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1
    assert "--trajectory" in p.stderr and "does not exist" in p.stderr


def test_dynamic_rupture_stretches_the_bridge() -> None:
    """Pitois' (1 + Ca^1/2): the bridge breaks farther out and takes more energy."""
    d = case_dict(300.0, amount={"film_thickness": X0})
    d["amount"] = {"film_thickness": X0}
    d["liquid"]["contact_angle"] = 20.0
    static = run(d)
    d["phases"] = {"rupture": "dynamic"}
    dyn = run(d)
    assert dyn.outcome == static.outcome == "rebound"
    gap_static, gap_dyn = (r.trajectory["gap"][-1] for r in (static, dyn))
    ca = ETA * 0.5 * dyn.rebound_velocity / 0.072  # below the speed at rupture
    assert gap_dyn > gap_static * (1 + 0.5 * math.sqrt(ca))
    assert dyn.energy["bridge"] > static.energy["bridge"] > 0.0
    assert abs(dyn.diagnostics["energy_residual"]) < 1e-9
