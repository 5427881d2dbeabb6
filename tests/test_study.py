"""Study files: grids, Latin hypercubes, derived axes, and one-line errors for bad files.

Array comparisons pass ``atol=0`` (``abs=0`` to approx): np.allclose's default atol 1e-8
(approx's 1e-12) would otherwise dominate the stated rtol for ratios of 0.001..1.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from wetcontact.cli import main
from wetcontact.errors import CaseError
from wetcontact.study import latin_hypercube, load_study

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "cases" / "studies"
BASE_FILM = ROOT / "cases" / "glass-2mm-water-film.toml"
BASE_BRIDGE = ROOT / "cases" / "dem-pendular-bridge-100um.toml"


def write(tmp_path: Path, body: str, base: Path = BASE_FILM, name: str = "s.toml") -> Path:
    p = tmp_path / name
    p.write_text(f'name = "t"\nbase = "{base}"\n' + body, encoding="utf-8")
    return p


def test_gaps_over_film_and_over_the_bridges_edge_gap(tmp_path):
    """The finite-liquid factors' coordinates: S/delta for films, S/H for bridges with
    Pitois' edge gap H = sqrt(S^2 + V/(pi R*))."""
    st = load_study(STUDIES / "calibrate-finite-liquid.toml")
    for _, sc in st.scenes:
        assert np.allclose(sc.gap_array / sc.film_thickness, np.linspace(0.01, 0.95, 10),
                           rtol=1e-14, atol=0)
    st = load_study(STUDIES / "calibrate-finite-liquid-bridge-ss.toml")
    assert {round(sc.radius2 / sc.radius, 9) for _, sc in st.scenes} == {
        round(x, 9) for x in np.geomspace(1.0, 10.0, 5)}
    for _, sc in st.scenes:
        rstar = sc.radius * sc.radius2 / (sc.radius + sc.radius2)
        h = np.sqrt(sc.gap_array**2 + sc.bridge_volume / (math.pi * rstar))
        assert np.allclose(sc.gap_array / h, np.linspace(0.01, 0.95, 8), rtol=1e-12, atol=0)
        assert sc.contact_angle_sphere == 0.0


def test_grid_study_replaces_fields_and_fills_axes():
    st = load_study(STUDIES / "stokes-immersed-16.toml")
    assert len(st.scenes) == 16 and st.axes == ("geometry.radius", "liquid.viscosity")
    pts = st.points()
    assert len(pts) == 32 and {p.model for p in pts} == {"stokes", "brenner"}
    assert all(p.preset == "fast" for p in pts)
    radii = sorted({p.scene.radius for p in pts})
    assert radii == [5e-4, 1e-3, 2e-3, 4e-3]
    for p in pts:  # each point's scene holds its own axis values; gaps are S/R x R
        assert p.scene.radius == p.axes["geometry.radius"]
        assert p.scene.viscosity == p.axes["liquid.viscosity"]
        assert np.allclose(p.scene.gap_array / p.scene.radius, [0.01, 0.1, 1.0], rtol=1e-15, atol=0)
    # first axis slowest
    assert [p.axes["liquid.viscosity"] for p in pts[:8:2]] == [1e-3, 0.1, 1.2, 10.0]


def test_range_axis_and_derived_dimensionless_axes(tmp_path):
    p = write(tmp_path, '''models = ["reynolds"]
[axes]
"motion.capillary_number" = { start = 1e-4, stop = 1e-2, points = 3, spacing = "log" }
"amount.film_over_radius" = [0.05, 0.1]
[set]
"motion.gap_over_radius" = { start = 0.04, stop = 0.001, points = 4, spacing = "log" }
''')
    st = load_study(p)
    assert len(st.points()) == 6
    for ax, sc in st.scenes:
        assert math.isclose(sc.velocity * sc.viscosity / sc.surface_tension,
                            ax["motion.capillary_number"], rel_tol=1e-14)
        assert math.isclose(sc.film_thickness, ax["amount.film_over_radius"] * sc.radius,
                            rel_tol=1e-14)
        assert np.allclose(sc.gap_array / sc.radius, np.geomspace(0.04, 0.001, 4), rtol=1e-14,
                           atol=0)
    assert [ax["motion.capillary_number"] for ax, _ in st.scenes[::2]] == pytest.approx(
        [1e-4, 1e-3, 1e-2], rel=1e-14, abs=0)


def test_amount_and_angle_fields_switch_cleanly(tmp_path):
    p = write(tmp_path, '''models = ["willett"]
[axes]
"amount.volume_over_radius3" = [0.01]
"liquid.contact_angle_sphere" = [10.0, 30.0]
[set]
"geometry.kind" = "sphere-sphere"
"motion.gaps" = [1e-6, 1e-5]
''')
    st = load_study(p)  # the film base becomes a bridge between two spheres
    for ax, sc in st.scenes:
        assert sc.amount == "bridge" and sc.film_thickness is None
        assert math.isclose(sc.bridge_volume, 0.01 * sc.radius**3, rel_tol=1e-14)
        assert math.isclose(math.degrees(sc.contact_angle_sphere),
                            ax["liquid.contact_angle_sphere"])
        assert math.degrees(sc.contact_angle_wall) == pytest.approx(20.0)  # base's angle kept


def test_gaps_over_rupture_distance_against_the_meniscus_model(tmp_path):
    from wetcontact.models import get_model

    p = write(tmp_path, '''models = ["meniscus"]
[axes]
"liquid.contact_angle" = [30.0]
[set]
"motion.gap_over_rupture" = [0.25, 0.5, 0.99]
''', base=BASE_BRIDGE)
    (_, sc), = load_study(p).scenes
    curve = get_model("meniscus").force(sc, preset="default")
    s_c = curve.extras["rupture_distance"][0]  # 128 elements; the study used 64
    assert np.allclose(sc.gap_array / s_c, [0.25, 0.5, 0.99], rtol=1e-6, atol=0)
    assert np.all(curve.extras["bridge_exists"] == 1.0)  # 0.99 S_c is still a bridge


def test_rupture_distances_are_solved_once_across_loads(tmp_path, monkeypatch):
    """Every load of a study (sweep, export csv, a rerun) solved its bridges' rupture
    distances again, about 0.5 s each (108 s for 200 bridges, silently); they are now kept
    in the user cache as they are solved, so the next load, in any process, solves none."""
    import wetcontact.solver.meniscus as men
    from wetcontact import study as study_mod

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    solved = []
    inner = men.rupture_distance

    def counting(*args, **kwargs):
        solved.append(args[1])
        return inner(*args, **kwargs)

    monkeypatch.setattr(men, "rupture_distance", counting)
    p = write(tmp_path, '''models = ["willett"]
[axes]
"amount.volume_over_radius3" = [1e-3, 1e-2]
"liquid.contact_angle" = [10.0, 30.0]
[set]
"motion.gap_over_rupture" = [0.5]
''', base=BASE_BRIDGE)
    gaps = []
    for _ in range(2):  # the second load as a new process would make it: caches emptied
        study_mod._rupture_distance.cache_clear()
        study_mod._rupture_cache.cache_clear()
        gaps.append([sc.gap_array[0] for _, sc in load_study(p).scenes])
    assert len(solved) == 4 and gaps[0] == gaps[1]
    assert len(list((tmp_path / "cache" / "wetcontact").glob("study_rupture-*.jsonl"))) == 1


def test_latin_hypercube_is_stratified_seeded_and_mapped(tmp_path, monkeypatch):
    """The design's strata, seed and mapping to the axes. The shipped held-out study's
    gaps are fractions of each bridge's rupture distance, which the sampling does not
    depend on: a stand-in (V^(1/3), Lian's leading term) spares 40 meniscus solves (40 s
    on a cold cache); the solved distances are tested above."""
    from wetcontact import study as study_mod

    monkeypatch.setattr(study_mod, "_rupture_distance",
                        lambda r1, r2, th1, th2, sigma, volume: volume ** (1.0 / 3.0))
    u = latin_hypercube(50, 3, seed=7)
    for j in range(3):  # one sample in each of the 50 strata of every column
        assert sorted(np.floor(u[:, j] * 50).astype(int)) == list(range(50))
    assert np.array_equal(u, latin_hypercube(50, 3, seed=7))
    assert not np.array_equal(u, latin_hypercube(50, 3, seed=8))
    st = load_study(STUDIES / "bridge-held-out.toml")
    v = np.array([ax["amount.volume_over_radius3"] for ax, _ in st.scenes])
    th = np.array([ax["liquid.contact_angle"] for ax, _ in st.scenes])
    assert len(v) == 40 and v.min() >= 1e-3 and v.max() <= 0.1
    assert th.min() >= 0 and th.max() <= 50
    strata = np.floor(np.log(v / 1e-3) / np.log(100) * 40).astype(int)  # log spacing
    assert sorted(strata) == list(range(40))


BAD = [
    ('models = ["reynolds"]\nfoo = 1\n', "foo = 1", "known keys"),
    ('models = ["nosuch"]\n', "models[0] = 'nosuch'", "reynolds"),
    ('models = []\n', "models = []", "non-empty list"),
    ('models = ["reynolds"]\npreset = "best"\n', "preset = 'best'", "fast"),
    ('models = ["reynolds"]\n[axes]\n"liquid.visc" = [1.0]\n', "axes = 'liquid.visc'",
     "case-file field path"),
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = []\n', "axes.liquid.viscosity = []",
     "list of 1 to"),
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = {start=1, stop=2, points=0}\n',
     "axes.liquid.viscosity.points = 0", "[1, 100000]"),
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = {start=-1, stop=2, points=3, '
     'spacing="log"}\n', "axes.liquid.viscosity.start = -1.0", "spacing = 'log'"),
    ('models = ["reynolds"]\n[axes]\n"liquid.contact_angle" = [10.0, 190.0]\n',
     "axes.liquid.contact_angle = 190.0", "[0, 180) degrees"),
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = [1e-3, -1.0]\n',
     "axes.liquid.viscosity = -1.0", "Pa s"),
    ('models = ["reynolds"]\n[axes]\n"amount.volume_over_radius3" = [50.0]\n',
     "axes.amount.volume_over_radius3 = 50.0", "amount.bridge_volume"),
    ('models = ["reynolds"]\n[set]\n"motion.gap_over_radius" = [0.01, 200.0]\n',
     "set.motion.gap_over_radius = [0.01, 200.0]", "motion.gaps"),
    ('models = ["reynolds"]\n[set]\n"liquid.viscosity" = 1.0\n[axes]\n"liquid.viscosity" = '
     '[1.0]\n', "set.liquid.viscosity", "not both"),
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = {start=1, stop=2, points=1000}\n'
     '"liquid.density" = {start=1, stop=2, points=1000}\n', "axes = '1000000 grid points'",
     "at most 100000"),
    ('models = ["reynolds"]\n[sample]\nmethod = "latin-hypercube"\npoints = 10\n'
     '[axes]\n"liquid.viscosity" = {min = 1e-3, max = 1.0}\n', "sample.seed missing",
     "integer >= 0"),
    ('models = ["reynolds"]\n[sample]\nmethod = "latin-hypercube"\npoints = 10\nseed = 1\n'
     '[axes]\n"liquid.viscosity" = [1e-3, 1.0]\n', "axes.liquid.viscosity = [0.001, 1.0]",
     "{min, max, spacing}"),
    ('models = ["reynolds"]\n[axes\n', "(syntax)", "valid TOML"),
    ('models = ["meniscus"]\n[set]\n"motion.gap_over_rupture" = [0.5]\n',
     "set.motion.gap_over_rupture = [0.5]", "bridge"),
    ('models = ["lubrication"]\n[set]\n"motion.gap_over_edge_gap" = [0.5]\n',
     "set.motion.gap_over_edge_gap = [0.5]", "bridge"),
    ('models = ["lubrication"]\n[set]\n"amount.volume_over_radius3" = 0.01\n'
     '"motion.gap_over_edge_gap" = [0.5, 1.0]\n', "set.motion.gap_over_edge_gap = [0.5, 1.0]",
     "[0, 1)"),
    # two entries for one field: the later silently won (a new user's audit, 2026-11-25)
    ('models = ["brenner"]\n[axes]\n"amount.film_over_radius" = [0.01]\n'
     '"amount.immersed" = [true]\n', "axes.amount.immersed", "one entry for amount"),
    ('models = ["reynolds"]\n[set]\n"motion.gap_over_radius" = [0.1]\n"motion.gaps" = '
     '[1e-5]\n', "set.motion.gaps", "one entry for motion.gaps (set.motion.gap_over_radius"),
    # a repeated value was one point, listed once by sweep and three times by export csv
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = [1e-3, 1e-3, 1e-3]\n',
     "axes.liquid.viscosity", "distinct values"),
    ('models = ["reynolds"]\n[axes]\n"liquid.viscosity" = {start=1, stop=1, points=3}\n',
     "axes.liquid.viscosity", "distinct values"),
]


@pytest.mark.parametrize(("body", "shown", "allowed"), BAD)
def test_bad_study_files_one_line_naming_file_key_value(tmp_path, capsys, body, shown,
                                                        allowed):
    p = write(tmp_path, body)
    with pytest.raises(CaseError) as err:
        load_study(p)
    msg = str(err.value)
    assert msg.startswith(f"{p}: ") and shown in msg and allowed in msg and "\n" not in msg
    assert main(["sweep", str(p), "--store", str(tmp_path / "r.h5")]) == 2
    out = capsys.readouterr()
    assert out.err.count("\n") == 1 and shown in out.err and "Traceback" not in out.err
    assert not (tmp_path / "r.h5").exists()


def test_missing_study_and_missing_base(tmp_path):
    with pytest.raises(CaseError, match=r"nope.toml: \(file\) missing"):
        load_study(tmp_path / "nope.toml")
    p = tmp_path / "s.toml"
    p.write_text('name = "t"\nbase = "../no-case.toml"\nmodels = ["reynolds"]\n')
    with pytest.raises(CaseError, match=r"s.toml: \(file\) missing; allowed: an existing case"):
        load_study(p)


@pytest.fixture
def rupture_cache(tmp_path, monkeypatch):
    """Rupture distances solved in a test go to a cache under ``tmp_path``."""
    from wetcontact import study as study_mod

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    study_mod._rupture_cache.cache_clear()
    yield
    study_mod._rupture_cache.cache_clear()


# A bad value on a point of a study with gap_over_rupture: the rupture distance is solved
# from the point's scene, whose errors were all blamed on set.motion.gap_over_rupture with
# the pseudo-file "<study point>" (an audit, 2026-12). The bad value comes first, so no
# rupture distance is solved.
GAPS = '[set]\n"motion.gap_over_rupture" = [0.1, 0.5]\n'
MISBLAMED = [
    ('[axes]\n"liquid.contact_angle" = [200.0, 10.0]\n' + GAPS,
     "axes.liquid.contact_angle = 200.0", "[0, 180) degrees"),
    ('[axes]\n"liquid.contact_angle" = ["a", 10.0]\n' + GAPS,
     "axes.liquid.contact_angle = 'a'", "[0, 180) degrees"),
    (GAPS + '"geometry.radius" = -1.0\n[axes]\n"liquid.contact_angle" = [10.0, 20.0]\n',
     "set.geometry.radius = -1.0", "(1e-09, 10] m"),
    ('[axes]\n"amount.volume_over_radius3" = [5.0, 1e-3]\n' + GAPS,
     "axes.amount.volume_over_radius3 = 5.0", "amount.bridge_volume a number in (1e-30, "),
    ('[axes]\n"amount.volume_over_radius3" = ["a", 1e-3]\n' + GAPS,
     "axes.amount.volume_over_radius3 = 'a'", "a finite number"),
    # the other derived fields that read the point's plain fields
    ('[set]\n"geometry.radius" = "x"\n"amount.volume_over_radius3" = 0.01\n'
     '"motion.gap_over_rupture" = [0.5]\n', "set.geometry.radius = 'x'", "(1e-09, 10] m"),
    ('[set]\n"amount.bridge_volume" = -1.0\n"motion.gap_over_edge_gap" = [0.5]\n',
     "set.amount.bridge_volume = -1.0", "(1e-30, "),
]


@pytest.mark.parametrize(("body", "shown", "allowed"), MISBLAMED, ids=[
    "axis-angle-200", "axis-angle-a", "set-radius-negative", "axis-volume-over-r3-5",
    "axis-volume-over-r3-a", "set-radius-x-with-volume-over-r3", "set-volume-with-edge-gap"])
def test_bad_point_blames_the_entry_that_set_the_field(tmp_path, capsys, body, shown,
                                                       allowed):
    p = write(tmp_path, 'models = ["willett", "mikami"]\n' + body, base=BASE_BRIDGE)
    with pytest.raises(CaseError) as err:
        load_study(p)
    msg = str(err.value)
    assert msg.startswith(f"{p}: {shown}; allowed: ") and allowed in msg, msg
    assert "gap_over" not in msg and "<study point>" not in msg and "\n" not in msg
    store = tmp_path / "r.h5"
    runs = [["sweep", str(p), "--workers", "0", "--store", str(store)],
            # calibrate loads its study the same way, before it sweeps or writes anything
            ["calibrate", str(p), "--closure", "finite-liquid", "--workers", "0", "--store",
             str(store), "--out", str(tmp_path / "out" / "c.json")]]
    for argv in runs:
        assert main(argv) == 2
        err_text = capsys.readouterr().err
        assert err_text == f"wetcontact: error: {msg}\n"
    assert not store.exists() and not (tmp_path / "out").exists()


GAP_RANGE = ("a number in [1e-12, 0.005] m (the lower limit, max(1e-12 m, 1e-9 R_s), is "
             "below the molecular scale)")
BAD_RUPTURE_GAPS = [
    ("[0.0, 0.5]", "set.motion.gap_over_rupture = [0.0, 0.5]",
     f"a value giving motion.gaps[0] {GAP_RANGE} (it gave 0.0)"),
    ("[0.5, -0.5]", "set.motion.gap_over_rupture = [0.5, -0.5]",
     f"a value giving motion.gaps[1] {GAP_RANGE} (it gave -"),
    ("[0.5, 1e6]", "set.motion.gap_over_rupture = [0.5, 1000000.0]",
     f"a value giving motion.gaps[1] {GAP_RANGE} (it gave "),
]


@pytest.mark.parametrize(("gaps", "shown", "allowed"), BAD_RUPTURE_GAPS,
                         ids=["zero", "negative", "huge"])
def test_bad_gap_over_rupture_is_still_blamed(tmp_path, rupture_cache, gaps, shown,
                                              allowed):
    p = write(tmp_path, f'models = ["willett"]\n[set]\n"motion.gap_over_rupture" = {gaps}\n'
              '"liquid.contact_angle" = 10.0\n', base=BASE_BRIDGE)
    with pytest.raises(CaseError) as err:
        load_study(p)
    msg = str(err.value)
    assert msg.startswith(f"{p}: {shown}; allowed: {allowed}"), msg
    assert "liquid.contact_angle" not in msg and "\n" not in msg


def test_radius_axis_with_derived_gaps_ignores_the_bases_gaps(tmp_path, rupture_cache):
    """The base's gaps (up to 13 um) exceed 100 R at R = 0.1 um, but gap_over_rupture
    replaces them: the rupture distance was solved from a scene holding them, and the
    valid study was refused."""
    p = write(tmp_path, 'models = ["willett"]\n[axes]\n"geometry.radius" = [1e-7]\n[set]\n'
              '"amount.volume_over_radius3" = 0.01\n"motion.gap_over_rupture" = [0.5]\n',
              base=BASE_BRIDGE)
    (_, sc), = load_study(p).scenes
    assert sc.radius == 1e-7 and 0.0 < sc.gaps[0] < 100 * sc.radius


def test_an_oversized_grid_is_refused_before_its_values_are_scanned(tmp_path):
    """A 1e7-point grid was scanned for repeated values (quadratic in an axis' length:
    150 s for 1e5 values) before its size was checked; now the size comes first, and the
    repeat check is linear (numbers compared as numbers)."""
    p = write(tmp_path, 'models = ["reynolds"]\n[axes]\n'
              '"liquid.contact_angle" = {start=1, stop=10, points=100000}\n'
              '"liquid.viscosity" = {start=1e-3, stop=2e-3, points=100}\n')
    with pytest.raises(CaseError, match="10000000 grid points"):
        load_study(p)
    p = write(tmp_path, 'models = ["reynolds"]\n[axes]\n"liquid.viscosity" = [1e-3, 2e-3, 1e-3]\n')
    with pytest.raises(CaseError, match=r"0\.001 appears more than once"):
        load_study(p)


def test_a_deeply_nested_study_file_is_a_case_error(tmp_path):
    p = write(tmp_path, "x = " + "[" * 3000 + "]" * 3000 + "\n")
    with pytest.raises(CaseError, match="nesting too deep"):
        load_study(p)
