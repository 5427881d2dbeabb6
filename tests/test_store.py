"""Reference store: round trip, content keys, conflicts, and survival of a SIGKILL."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from conftest import make_scene

from wetcontact.models import MODELS, ForceCurve
from wetcontact.store import Store, StoreConflictError, curve_key


def test_round_trip_with_provenance(tmp_path):
    sc = make_scene()
    curve = MODELS["brenner"].force(sc)
    st = Store(tmp_path / "ref.h5")
    key = st.save(sc, curve)
    back = st.load(key)
    assert np.array_equal(back.gap, curve.gap)
    assert np.array_equal(back.force_viscous, curve.force_viscous)
    assert back.force_capillary is None
    assert back.provenance["wetcontact"] == curve.provenance["wetcontact"]
    assert "numpy" in back.provenance and "git_commit" in back.provenance
    assert back.diagnostics["wall_time_s"] >= 0
    assert st.find(model="brenner") == [key]
    assert st.get(sc, curve) is not None


def test_same_key_same_data_is_noop_other_data_is_error(tmp_path):
    sc = make_scene()
    curve = MODELS["reynolds"].force(sc)
    st = Store(tmp_path / "ref.h5")
    k1 = st.save(sc, curve)
    mtime = os.stat(st.path).st_mtime_ns
    assert st.save(sc, curve) == k1 and os.stat(st.path).st_mtime_ns == mtime
    tampered = ForceCurve(case=curve.case, model=curve.model, gap=curve.gap,
                          force_viscous=curve.force_viscous * 1.01, force_capillary=None,
                          settings=curve.settings)
    with pytest.raises(StoreConflictError, match="already holds other force_viscous"):
        st.save(sc, tampered)
    assert len(st) == 1


def test_key_depends_on_scene_model_and_settings():
    a, b = make_scene(), make_scene(motion={"velocity": 0.2, "gaps": [1e-5, 1e-4]})
    assert curve_key(a, "m", {}) != curve_key(b, "m", {})
    assert curve_key(a, "m", {}) != curve_key(a, "n", {})
    assert curve_key(a, "m", {"preset": "fast"}) != curve_key(a, "m", {"preset": "default"})
    assert curve_key(a, "m", {}) == curve_key(make_scene(), "m", {})


WRITER = textwrap.dedent("""
    import sys, numpy as np
    sys.path.insert(0, {tests!r})
    from conftest import make_scene
    from wetcontact.models import ForceCurve
    from wetcontact.store import Store
    st = Store({path!r})
    big = np.linspace(1.0, 2.0, 100_000)   # large curves make each write take a while
    for i in range(1000):
        sc = make_scene(motion={{"velocity": 0.1 + i, "gaps": [1e-5]}})
        cv = ForceCurve(case=sc.name, model="m", gap=[1e-5], force_viscous=[float(i)],
                        force_capillary=None, extras={{}}, diagnostics={{"blob": 0}})
        st.save_many([(sc, cv)])
        # a second, big curve under a different model keeps the writer busy in h5py
        sc2 = make_scene(motion={{"velocity": 0.1 + i, "gaps": {{"start": 1e-5, "stop": 1e-4,
                                                               "points": 100_000}}}})
        cv2 = ForceCurve(case=sc2.name, model="big", gap=sc2.gap_array, force_viscous=big,
                         force_capillary=None, extras={{"a": big, "b": big, "c": big}})
        st.save_many([(sc2, cv2)])
        print(i, flush=True)
""")


def test_sigkill_mid_write_keeps_everything_saved_before(tmp_path):
    path = tmp_path / "ref.h5"
    tests = os.path.dirname(__file__)
    proc = subprocess.Popen([sys.executable, "-c", WRITER.format(tests=tests, path=str(path))],
                            stdout=subprocess.PIPE, text=True)
    done = []
    while len(done) < 4:
        line = proc.stdout.readline()
        assert line, "writer died early"
        done.append(int(line))
    time.sleep(0.05)  # land inside a later write (each takes tens of ms)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    st = Store(path)
    forces = {float(st.load(k).force_viscous[0]) for k in st.find(model="m")}
    assert {float(i) for i in done} <= forces  # everything confirmed before the kill
    for k in st.find(model="big"):
        assert st.load(k).gap.size == 100_000  # no torn curve
    # at most the killed write's temporary file, beside the lock file (kept, empty)
    leftovers = [p for p in tmp_path.iterdir() if p.name not in ("ref.h5", "ref.h5.lock")]
    assert len(leftovers) <= 1


def test_unreadable_store_paths_are_input_errors(tmp_path):
    """A folder given as the store was reported with h5py's whole errno dump."""
    from wetcontact.errors import InputError

    (tmp_path / "folder").mkdir()
    with pytest.raises(InputError, match="a folder; allowed: an HDF5 store file"):
        len(Store(tmp_path / "folder"))
    (tmp_path / "junk.h5").write_text("not hdf5")
    with pytest.raises(InputError, match="not a readable HDF5 store"):
        len(Store(tmp_path / "junk.h5"))


# ---- a durability audit (2026-11-27): each test failed on the code before it ---------------


def _one(tmp_path, name="s.h5"):
    sc = make_scene()
    st = Store(tmp_path / name)
    st.save(sc, MODELS["brenner"].force(sc))
    return st, sc


def test_a_symlinked_store_writes_its_target(tmp_path):
    """The atomic replace turned the link into a plain file and left the real store as it
    was; the link and the target also took different locks."""
    (tmp_path / "real").mkdir()
    st, sc = _one(tmp_path / "real")
    link = tmp_path / "link.h5"
    link.symlink_to(st.path)
    via = Store(link)
    via.save(sc, MODELS["cox-brenner"].force(sc))
    assert link.is_symlink() and len(Store(st.path)) == 2
    assert via.lock_path == st.lock_path


def test_an_unwritable_store_is_refused_before_any_work(tmp_path):
    from wetcontact.errors import InputError

    st, _ = _one(tmp_path)
    os.chmod(st.path, 0o444)  # refused by its mode, so as root too
    with pytest.raises(InputError, match=r"s\.h5: the store file is read-only \(mode 444\)"):
        st.check_writable()
    long = Store(tmp_path / ("b" * 247 + ".h5"))  # fits, but its temporary copy does not
    with pytest.raises(InputError, match="no room for its temporary copy"):
        long.check_writable()


def test_a_foreign_or_damaged_file_is_an_input_error(tmp_path):
    import h5py

    from wetcontact.errors import InputError

    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["curves"] = np.zeros(3)
    with pytest.raises(InputError, match="not a wetcontact store .'curves' is a Dataset"):
        Store(foreign).check_writable()
    st, sc = _one(tmp_path)
    key = st.keys()[0]
    with h5py.File(st.path, "a") as f:
        del f["curves"][key].attrs["settings"]
    with pytest.raises(InputError, match=f"curve {key} is damaged"):
        st.load(key)


def test_a_killed_writers_temporary_copy_is_removed(tmp_path):
    st, sc = _one(tmp_path)
    stale = tmp_path / "s.h5.ab12_xYz.tmp"  # mkstemp's pattern; as a kill -9 leaves it
    stale.write_bytes(b"x" * 1000)
    other = tmp_path / "s.h5.notes.tmp"  # not a copy of this store: kept
    other.write_text("keep")
    st.save(sc, MODELS["cox-brenner"].force(sc))
    assert not stale.exists() and other.exists()
