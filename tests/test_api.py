"""The Python API as a notebook user meets it (an audit, 2026-11-27): each test failed on
the code before it."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from conftest import make_scene

from wetcontact.compare import compare
from wetcontact.errors import InputError
from wetcontact.models import get_model
from wetcontact.store import Store

BRIDGE = {"bridge_volume": 1e-12}


def _bridge(gaps=(1e-6, 1e-5, 5e-5)):
    return make_scene(amount=BRIDGE, motion={"velocity": 0.01, "gaps": list(gaps)})


def test_a_curve_is_stored_under_its_own_scene_only(tmp_path):
    """The store kept a curve under another scene's key and returned it as that scene's."""
    st = Store(tmp_path / "s.h5")
    sc = _bridge()
    c = get_model("willett").force(sc)
    with pytest.raises(InputError, match="saved under scene"):
        st.save(sc.with_gaps([2e-6]), c)
    other = make_scene(name="other", amount=BRIDGE, motion={"velocity": 0.01,
                                                            "gaps": list(sc.gaps)})
    with pytest.raises(InputError, match="curve of 'test-scene'"):
        st.save(other, c)
    assert len(st) == 0
    st.save(sc, c)
    assert len(st) == 1


def test_get_by_model_name_finds_a_curve_saved_at_its_defaults(tmp_path):
    """Store.get(scene, "willett") looked the curve up with settings {} and never found it."""
    st = Store(tmp_path / "s.h5")
    sc = _bridge()
    st.save(sc, get_model("willett").force(sc))
    st.save(sc, get_model("lubrication").force(sc, preset="fast"))
    assert st.get(sc, "willett") is not None
    assert st.get(sc, "lubrication") is None  # only its fast preset is stored
    got = st.get(sc, "lubrication", {"preset": "fast"})
    assert got is not None and got.settings["preset"] == "fast"


def test_total_is_compared_only_between_curves_of_the_same_components():
    """A viscous-only and a capillary-only curve were compared as totals (error 1.02)."""
    sc = _bridge()
    lub, men = get_model("lubrication").force(sc), get_model("meniscus").force(sc)
    with pytest.raises(InputError, match="same force components"):
        compare(lub, men, "total")
    assert compare(get_model("willett").force(sc), men, "total").points == 3


def test_curves_stay_read_only_through_pickle():
    """ForceCurve.gap was writable (a notebook could corrupt a 'frozen' curve), and an
    unpickled curve (back from a worker) had every array writable."""
    c = get_model("willett").force(_bridge())
    for curve in (c, pickle.loads(pickle.dumps(c))):
        arrays = [curve.gap, curve.force_capillary, *curve.extras.values()]
        assert not any(a.flags.writeable for a in arrays)
        with pytest.raises(ValueError):
            curve.gap[0] = 99.0
    back = pickle.loads(pickle.dumps(c))
    assert np.array_equal(back.force_capillary, c.force_capillary) and back.case == c.case


def test_numpy_scalars_are_numbers():
    """np.float32 / np.int64 values were refused as out of range ('np.float32(0.001);
    allowed: a number in (1e-09, 10] m')."""
    sc = make_scene(geometry={"kind": "sphere-wall", "radius": np.float32(1e-3)},
                    amount={"bridge_volume": np.float64(1e-12)},
                    motion={"velocity": np.int64(1), "gaps": [np.float32(1e-6), 2e-6]})
    assert sc.radius == pytest.approx(1e-3, rel=1e-7) and isinstance(sc.radius, float)
    assert sc.with_gaps(np.float32(1e-6)).gaps == (float(np.float32(1e-6)),)
    from wetcontact import select

    curve, _ = select.solve(sc, np.float32(0.05))
    assert curve.force_capillary is not None
    with pytest.raises(InputError, match="tolerance = True"):
        select.solve(sc, True)
    with pytest.raises(InputError, match="geometry.radius"):
        make_scene(geometry={"kind": "sphere-wall", "radius": np.bool_(True)})


def test_force_of_something_else_than_a_scene_is_an_input_error():
    with pytest.raises(InputError, match="allowed: a Scene"):
        get_model("willett").force({"a": 1})


def test_capillary_closures_flag_volumes_below_their_measured_range():
    """At V* = 1e-20 Mikami's fit pushed (+9.5e-5 N) with no note."""
    tiny = make_scene(amount={"bridge_volume": 1e-29}, motion={"velocity": 0.0,
                                                              "gaps": [1e-12]})
    for name in ("mikami", "willett-simple", "rabinovich", "lambert"):
        note = get_model(name).force(tiny).diagnostics.get("outside_stated_validity", "")
        assert "< 0.0001, below the range" in note, name
    ok = get_model("mikami").force(_bridge())
    assert "outside_stated_validity" not in ok.diagnostics


def test_unknown_options_are_input_errors():
    """A closure took any keyword silently and recorded it in its settings (so in the
    store's key); stokes raised TypeError from its mesh resolution."""
    with pytest.raises(InputError, match=r"'willett': unknown option\(s\) \['foo'\]"):
        get_model("willett").force(_bridge(), foo=1)
    immersed = make_scene(motion={"velocity": 0.01, "gaps": [1e-4]})
    with pytest.raises(InputError, match=r"'stokes': unknown option\(s\) \['nn'\]"):
        get_model("stokes").force(immersed, preset="fast", nn=3)
    assert get_model("stokes").force(immersed, preset="fast", n_gap=3).force_viscous[0] > 0


def test_meniscus_names_the_toroid_below_the_volumes_it_resolves():
    """A bridge of V/R^3 = 1e-12 was refused with 'the contact angles or the volume admit no
    bridge' (InputError), and calibrated-capillary sent the user there."""
    from wetcontact.errors import ValidityError

    tiny = make_scene(amount={"bridge_volume": 1e-12 * 1e-9},
                      motion={"velocity": 0.0, "gaps": [1e-9]})
    with pytest.raises(ValidityError, match="use model 'toroidal'"):
        get_model("meniscus").force(tiny)
    f = get_model("toroidal").force(tiny).force_capillary[0]
    small = make_scene(amount={"bridge_volume": 3e-11 * 1e-9},
                       motion={"velocity": 0.0, "gaps": [1e-9]})
    fm = get_model("meniscus").force(small).force_capillary[0]
    ft = get_model("toroidal").force(small).force_capillary[0]
    assert f < 0 and abs(ft / fm - 1) < 2e-4


def test_with_gaps_keeps_the_film_rule_of_the_case_file():
    """with_gaps accepted gaps all above the film, which the loader refuses; the models then
    disagreed (zero, a force, refusals)."""
    from wetcontact.errors import CaseError

    film = make_scene(amount={"film_thickness": 1e-4}, motion={"velocity": 0.1,
                                                               "gaps": [5e-5]})
    with pytest.raises(CaseError, match="the smallest gap 0.0002 m"):
        film.with_gaps([2e-4, 3e-4])
    assert film.with_gaps([2e-4, 5e-5]).gaps == (2e-4, 5e-5)


@pytest.mark.parametrize("gaps", ["abc", {"start": 1e-6, "stop": 1e-7, "points": 3}, 10**400,
                                  [1e-6, None], True, [[1e-6, 2e-6]], [1e-6, False]])
def test_bad_gaps_in_force_are_input_errors(gaps):
    """ValueError, TypeError and OverflowError came out of numpy; None became nan blamed on
    the case file; True became a gap of 1 m."""
    with pytest.raises(InputError, match="gaps = .*allowed: a number or a list of numbers"):
        get_model("willett").force(_bridge(), gaps=gaps)


def test_numeric_gaps_in_any_form_are_taken():
    m, sc = get_model("willett"), _bridge()
    want = m.force(sc, gaps=[1e-6, 2e-6]).force_capillary
    for g in (np.array([1e-6, 2e-6]), (1e-6, 2e-6), [np.float64(1e-6), 2e-6]):
        assert np.array_equal(m.force(sc, gaps=g).force_capillary, want)


def test_a_model_name_or_preset_that_is_not_a_string_is_an_input_error():
    with pytest.raises(InputError, match="a model name"):
        get_model(["willett"])
    with pytest.raises(InputError, match="preset = \\['default'\\]"):
        get_model("willett").force(_bridge(), preset=["default"])


def test_toroidal_refuses_a_gap_without_a_toroid_wherever_it_is():
    """Its check probed the smallest gap only, so the same missing toroid was a refusal
    (exit 2) for gaps = [5e-5] and a solver failure (exit 1) for [5e-6, 5e-5]."""
    from wetcontact.errors import ValidityError

    def scene(gaps):
        return make_scene(geometry={"kind": "sphere-sphere", "radius": 5e-5},
                          liquid={"viscosity": 1e-3, "surface_tension": 0.072,
                                  "density": 998.0, "contact_angle": 77.0},
                          amount={"bridge_volume": 1.2e-13},
                          motion={"velocity": 0.01, "gaps": gaps})

    for gaps in ([5e-5], [5e-6, 5e-5]):
        with pytest.raises(ValidityError, match="no bridge of volume"):
            get_model("toroidal").force(scene(gaps))


def test_reynolds_finite_notes_a_liquid_edge_where_the_sphere_is_steep():
    """It answered silently with a wetted radius larger than the sphere (lubrication
    refuses such a bridge); a film as thick as the sphere got no note either."""
    big = make_scene(geometry={"kind": "sphere-sphere", "radius": 5e-5},
                     amount={"bridge_volume": 2.5e-13},
                     motion={"velocity": 0.01, "gaps": [1e-7]})
    note = get_model("reynolds-finite").force(big).diagnostics["outside_stated_validity"]
    assert "steeper than 60 deg" in note
    film = make_scene(amount={"film_thickness": 1e-3}, motion={"velocity": 0.01,
                                                              "gaps": [1e-5]})
    assert "steeper" in get_model("reynolds-finite").force(film).diagnostics[
        "outside_stated_validity"]
    ok = get_model("reynolds-finite").force(_bridge())
    assert "steeper" not in ok.diagnostics.get("outside_stated_validity", "")


def test_a_coefficient_file_nested_too_deep_is_an_input_error(tmp_path):
    from wetcontact.calibrate import load_coefficients

    p = tmp_path / "deep.json"
    p.write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(InputError, match="nested too deep"):
        load_coefficients(p)


def test_thinfilm_refuses_a_slow_film_before_its_steps_underflow():
    """At Ca* = 4e-6 the sharp contact's time steps failed after seconds of work ('step
    size underflow', exit 1; an input-fuzzing audit); its check now refuses Ca* below
    CA_STAR_MIN_SHARP up front, naming lubrication, and the penalty contacts keep theirs."""
    from wetcontact.errors import ValidityError
    from wetcontact.solver.thinfilm.model import CA_STAR_MIN_SHARP, reduced_capillary_number

    slow = make_scene(amount={"film_thickness": 1e-4},
                      motion={"velocity": 1e-6, "gaps": [5e-5, 1e-6]})
    assert reduced_capillary_number(slow) < CA_STAR_MIN_SHARP
    model = get_model("thinfilm")
    with pytest.raises(ValidityError, match=r"Ca\* = .* < 0\.0001.*lubrication"):
        model.check(slow)
    model.check_options(slow, {**model.presets["default"], "contact": "tangential"})
    fast = make_scene(amount={"film_thickness": 1e-4},
                      motion={"velocity": 1e-3, "gaps": [5e-5, 1e-6]})
    model.check(fast)
