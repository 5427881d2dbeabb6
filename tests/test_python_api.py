"""The Python API's conveniences (issue 58): contact angles in degrees on a ``Scene``, and
``ForceCurve.to_dataframe`` (pandas optional)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact import get_model, load_case
from wetcontact.errors import CaseError
from wetcontact.scene import scene_from_dict, with_angles_deg

ROOT = Path(__file__).resolve().parents[1]
BRIDGE = ROOT / "cases" / "dem-pendular-bridge-100um.toml"


def _pair(**liquid):
    return scene_from_dict({
        "name": "pair", "geometry": {"kind": "sphere-sphere", "radius": 1e-4, "radius2": 2e-4},
        "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0, **liquid},
        "amount": {"bridge_volume": 1e-13}, "motion": {"velocity": 0.01, "gaps": [1e-6]}})


def test_angles_in_degrees_equal_the_case_file_angles():
    """A scene changed through with_angles_deg equals one read with those angles."""
    base = _pair(contact_angle=10.0)
    want = _pair(contact_angle_sphere=30.0, contact_angle_sphere2=45.5)
    assert base.with_angles_deg(sphere=30.0, wall=45.5) == want
    assert with_angles_deg(base, sphere=30.0, wall=45.5) == want
    assert base.with_angles_deg(both=20).contact_angles_deg == pytest.approx((20.0, 20.0))
    one = base.with_angles_deg(wall=60.0)  # the other angle is kept
    assert one.contact_angle_sphere == base.contact_angle_sphere
    assert one.contact_angle_wall == math.radians(60.0)
    assert base.contact_angles_deg == pytest.approx((10.0, 10.0))


def test_angles_in_degrees_change_the_force():
    scene = load_case(BRIDGE)
    model = get_model("willett")
    wet, dry = (model.force(scene.with_angles_deg(both=a)).force_capillary for a in (0, 60))
    near = np.argmin(scene.gap_array)
    assert abs(dry[near]) < 0.6 * abs(wet[near])  # cos(60 deg) = 0.5: a weaker bridge


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"sphere": 180.0}, "liquid.contact_angle_sphere"),
    ({"wall": -1.0}, "liquid.contact_angle_sphere2"),
    ({"wall": float("nan")}, "liquid.contact_angle_sphere2"),
    ({"sphere": "30"}, "liquid.contact_angle_sphere"),
    ({"sphere": 10.0, "both": 20.0}, "liquid.contact_angle"),
])
def test_bad_angles_are_refused_naming_the_field(kwargs, field):
    with pytest.raises(CaseError, match=field.replace(".", r"\.")):
        _pair(contact_angle=10.0).with_angles_deg(**kwargs)


def test_wall_angle_of_a_sphere_wall_scene_is_named_as_in_a_case_file():
    scene = load_case(ROOT / "cases" / "sphere-plate-unequal-angles.toml")
    with pytest.raises(CaseError, match=r"liquid\.contact_angle_wall"):
        scene.with_angles_deg(wall=200.0)


def test_to_dataframe_has_the_forces_and_the_extras():
    pd = pytest.importorskip("pandas")
    scene = load_case(BRIDGE)
    curve = get_model("willett").force(scene)
    df = curve.to_dataframe()
    assert isinstance(df, pd.DataFrame) and len(df) == curve.gap.size
    assert list(df.columns[:2]) == ["gap", "force_capillary"]
    assert "force_viscous" not in df.columns  # not modelled: no column, not zeros
    np.testing.assert_array_equal(df["gap"].to_numpy(), curve.gap)
    np.testing.assert_array_equal(df["force_total"].to_numpy(), curve.force_total)
    for name, values in curve.extras.items():
        np.testing.assert_array_equal(df[name].to_numpy(), values)
    assert df.attrs["model"] == "willett" and df.attrs["case"] == scene.name
    df.loc[0, "gap"] = -1.0  # a copy: the curve's read-only arrays are untouched
    assert curve.gap[0] > 0
    both = get_model("reynolds-finite").force(scene).to_dataframe()
    assert {"force_viscous", "force_total"} <= set(both.columns)


def test_to_dataframe_without_pandas_says_how_to_install_it(monkeypatch):
    curve = get_model("reynolds").force(load_case(BRIDGE))
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas raises ImportError
    with pytest.raises(ImportError, match="pip install pandas"):
        curve.to_dataframe()


def test_the_guides_dataframe_example_runs():
    """The getting-started page's example with degrees and a DataFrame, as a user pastes it."""
    pytest.importorskip("pandas")
    import re
    import subprocess

    text = (ROOT / "docs" / "getting-started.md").read_text()
    block = next(b for b in re.findall(r"^```python\n(.*?)^```", text, re.M | re.S)
                 if "to_dataframe" in b)
    done = subprocess.run([sys.executable, "-c", block], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "force_capillary" in done.stdout and "e-0" in done.stdout
