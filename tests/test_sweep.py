"""Sweeps and the store around them: reuse, failure records, locks, code versions, file
modes, the Dask cluster (local and by address), and a SIGKILL mid-sweep."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import stat
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import make_scene

from wetcontact.cli import main
from wetcontact.models import get_model
from wetcontact.store import BatchWriter, Store, StoreBusyError, code_version, curve_key
from wetcontact.study import load_study
from wetcontact.sweep import Point, sweep

ROOT = Path(__file__).resolve().parents[1]
STOKES16 = ROOT / "cases" / "studies" / "stokes-immersed-16.toml"
BIN = Path(sys.executable).parent
ENV = {**os.environ, "PYTHONPATH": str(ROOT / "src")}


def study_file(tmp_path: Path, case: str, body: str) -> Path:
    """A study file on ``cases/<case>.toml`` with ``body`` after name and base."""
    base = ROOT / "cases" / f"{case}.toml"
    p = tmp_path / "s.toml"
    p.write_text(f'name = "s"\nbase = "{base}"\n' + body, encoding="utf-8")
    return p


def closure_points(n: int = 6) -> list[Point]:
    pts = []
    for i in range(n):
        sc = make_scene(motion={"velocity": 0.1 * (i + 1), "gaps": [1e-5, 1e-4]})
        pts += [Point(sc, "brenner"), Point(sc, "cox-brenner"), Point(sc, "meniscus")]
    return pts


def test_in_process_sweep_reuses_and_records_failures(tmp_path):
    st = Store(tmp_path / "r.h5")
    pts = closure_points()
    r1 = sweep(pts + pts[:3], st, workers=0, progress=False)  # duplicates solved once
    assert (r1.count("computed"), r1.count("reused"), r1.count("failed")) == (12, 0, 6)
    assert len(r1.outcomes) == len(pts) + 3 and r1.executor == "in-process"
    for p in pts[:2]:  # the values are the model's own
        direct = get_model(p.model).force(p.scene)
        assert np.array_equal(r1.curve(p).force_viscous, direct.force_viscous)
    refused = next(o for o in r1.outcomes if o.status == "failed")
    assert "immersed" in refused.reason and "stokes" in refused.reason
    assert st.failures()[refused.key] == refused.reason  # kept, so reruns know
    r2 = sweep(pts, st, workers=0, progress=False, keep_curves=False)
    assert (r2.count("computed"), r2.count("reused"), r2.count("failed")) == (0, 12, 6)
    assert np.array_equal(r2.curve(pts[0]).force_viscous, r1.curve(pts[0]).force_viscous)
    r3 = sweep(pts, st, workers=0, progress=False, retry_failed=True)
    assert r3.count("failed") == 6 and r3.count("computed") == 0
    assert r3.summary("s") == {"study": "s", "points": 18, "computed": 0, "reused": 12,
                               "failed": 6, "store": str(st.path),
                               "wall_time_s": round(r3.wall_time_s, 3)}


def test_local_cluster_has_no_more_workers_than_points(tmp_path):
    """--workers 64 for 4 points started 64 processes (56 s on 2 cores)."""
    pts = closure_points(1)[:2]
    r = sweep(pts, Store(tmp_path / "c.h5"), workers=6, progress=False)
    assert r.executor == "local-cluster:2", r.executor


def test_local_dask_cluster_gives_the_in_process_values(tmp_path):
    pts = closure_points(8)
    a = sweep(pts, Store(tmp_path / "a.h5"), workers=0, progress=False)
    b = sweep(pts, Store(tmp_path / "b.h5"), workers=2, progress=False)
    assert b.executor == "local-cluster:2" and b.tasks >= 2
    assert b.count("computed") == a.count("computed") == 16 and b.count("failed") == 8
    for p in pts:
        ca, cb = a.curve(p), b.curve(p)
        assert (ca is None) == (cb is None)
        if ca is not None:
            assert np.array_equal(ca.force_viscous, cb.force_viscous)


def test_workers_running_other_code_fail_their_points_unstored(tmp_path, monkeypatch):
    import wetcontact.sweep as sw

    monkeypatch.setattr(sw, "code_version", lambda: "0.0.0+client")  # workers: the real one
    st = Store(tmp_path / "r.h5")
    r = sweep(closure_points(2)[:2], st, workers=2, progress=False)
    assert r.count("failed") == 2 and r.count("computed") == 0
    assert all("0.0.0+client" in o.reason and code_version() in o.reason for o in r.outcomes)
    assert not st.path.exists() or (len(st) == 0 and not st.failures())


def test_key_holds_the_code_version_and_a_source_edit_changes_it(tmp_path):
    sc = make_scene()
    assert code_version().startswith(__import__("wetcontact").__version__ + "+")
    assert curve_key(sc, "m", {}, version="0.1.0+aaa") != curve_key(sc, "m", {},
                                                                      version="0.1.0+bbb")
    assert curve_key(sc, "m", {}) == curve_key(sc, "m", {}, version=code_version())
    pkg = tmp_path / "src" / "wetcontact"
    shutil.copytree(ROOT / "src" / "wetcontact", pkg,
                    ignore=shutil.ignore_patterns("__pycache__"))
    probe = [sys.executable, "-c", "from wetcontact.store import code_version as c; print(c())"]
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "src")}

    def version() -> str:
        return subprocess.run(probe, env=env, capture_output=True, text=True,
                              check=True).stdout.strip()

    v0 = version()
    assert v0 == code_version()  # same sources, same version
    (pkg / "report.py").write_text("# not numeric\n", encoding="utf-8")
    assert version() == v0
    with open(pkg / "reduced_models" / "viscous.py", "a", encoding="utf-8") as fh:
        fh.write("\n# an edit\n")
    assert version() != v0
    # one process keeps one version: a run whose sources are edited under it still finds,
    # in its report, the curves its sweep stored
    edit = ("from pathlib import Path; from wetcontact.store import code_version as c; a = c(); "
            f"Path({str(pkg / 'reduced_models' / 'viscous.py')!r}).open('a').write('# 2\\n'); "
            "print(a == c())")
    same = subprocess.run([sys.executable, "-c", edit], env=env, capture_output=True,
                          text=True, check=True).stdout.strip()
    assert same == "True"
    assert version() != v0


def test_store_file_mode_follows_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        sc = make_scene()
        st = Store(tmp_path / "r.h5")
        st.save(sc, get_model("brenner").force(sc))
        assert stat.S_IMODE(os.stat(st.path).st_mode) == 0o640
        os.chmod(st.path, 0o664)  # a later write keeps the file's mode
        st.save(sc, get_model("cox-brenner").force(sc))
        assert stat.S_IMODE(os.stat(st.path).st_mode) == 0o664
    finally:
        os.umask(old)


def test_batch_writer_writes_in_batches(tmp_path):
    st = Store(tmp_path / "r.h5")
    bw = BatchWriter(st, min_interval=3600)
    for p in closure_points(4)[::3]:
        bw.add(p.scene, get_model(p.model).force(p.scene))
        bw.maybe_flush()
    assert not st.path.exists() and len(bw.pending) == 4
    bw.flush()
    assert len(st) == 4 and bw.writes == 1 and bw.interval >= 3600
    capped = BatchWriter(st, min_interval=3600, max_batch=3)  # a full batch goes at once
    for p in closure_points(4)[1::3]:
        capped.add(p.scene, get_model(p.model).force(p.scene))
        capped.maybe_flush()
    assert capped.writes == 1 and len(capped.pending) == 1 and len(st) == 7


def test_a_finished_point_is_written_without_waiting_for_the_next(tmp_path):
    """A result was written only when the next one arrived: a 40 s Stokes point stayed
    unsaved while the next ran, and a SIGKILL lost it (a durability audit). While the
    sweep runs, a thread writes what is pending once the interval has passed."""
    st = Store(tmp_path / "r.h5")
    bw = BatchWriter(st, min_interval=0.2)
    p = closure_points(1)[0]
    with bw.background(poll=0.05):
        bw.last -= 1.0  # the last write long ago: the first result is due at once
        bw.add(p.scene, get_model(p.model).force(p.scene))
        deadline = time.monotonic() + 30.0
        while not st.path.exists() and time.monotonic() < deadline:
            time.sleep(0.05)  # no further add, no flush from this thread
        assert st.path.exists() and len(st) == 1 and not bw.pending
    bw.flush()
    assert bw.writes == 1


def test_a_background_write_error_reaches_the_caller(tmp_path):
    st = Store(tmp_path / "r.h5")
    bw = BatchWriter(st, min_interval=0.0)
    p = closure_points(1)[0]

    def broken(*_a, **_k):
        raise OSError("disk full")

    st.save_many = broken  # type: ignore[method-assign]
    with bw.background(poll=0.02):
        bw.add(p.scene, get_model(p.model).force(p.scene))
        deadline = time.monotonic() + 30.0
        while bw._error is None and time.monotonic() < deadline:
            time.sleep(0.02)
    with pytest.raises(OSError, match="disk full"):
        bw.flush()


def test_a_failed_store_write_stops_the_progress_lines(tmp_path, monkeypatch):
    """A sweep whose last write failed (a full disk) left its progress thread ticking:
    'sweep: 2/2 points' lines went on appearing in whatever ran next in the process."""
    import io

    st = Store(tmp_path / "r.h5")

    def broken(*_a, **_k):
        raise OSError("disk full")

    monkeypatch.setattr(Store, "save_many", broken)
    monkeypatch.setattr(sys, "stderr", io.StringIO())  # not a terminal: timed lines
    before = set(threading.enumerate())
    with pytest.raises(OSError, match="disk full"):
        sweep(closure_points(1)[:2], st, workers=0, progress=True)
    left = [t for t in set(threading.enumerate()) - before if t.is_alive()]
    assert left == [], left


HOLDER = textwrap.dedent("""
    import sys
    from wetcontact.store import Store
    with Store(sys.argv[1]).writer():
        print("locked", flush=True)
        sys.stdin.readline()  # holds the lock until the test says "release"
""")


def test_second_writer_waits_or_exits_2_with_one_line(tmp_path, capsys):
    path = tmp_path / "r.h5"
    holder = subprocess.Popen([sys.executable, "-c", HOLDER, str(path)], env=ENV,
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        sc = make_scene()
        with pytest.raises(StoreBusyError, match=r"in use by another process \(pid \d+"):
            Store(path, lock_timeout=0.2).save(sc, get_model("brenner").force(sc))
        study = study_file(tmp_path, "brenner-immersed-sphere-wall", 'models = ["brenner"]\n')
        assert main(["sweep", str(study), "--store", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "store is in use" in err
        # with a long enough wait the second writer goes through once the lock is freed:
        # the holder frees it 1 s from now, so the sweep cannot finish sooner however
        # loaded the machine is
        release = threading.Timer(1.0, lambda: (holder.stdin.write("release\n"),
                                                holder.stdin.flush()))
        t0 = time.monotonic()
        release.start()
        try:
            assert main(["sweep", str(study), "--store", str(path), "--wait", "30",
                         "--json"]) == 0
        finally:
            release.cancel()
        assert time.monotonic() - t0 >= 1.0
        assert json.loads(capsys.readouterr().out)["computed"] == 1
    finally:
        holder.kill()
        holder.wait()


WRITER = textwrap.dedent("""
    import sys
    sys.path.insert(0, sys.argv[3])
    from conftest import make_scene
    from wetcontact.models import get_model
    from wetcontact.store import Store
    st = Store(sys.argv[1], lock_timeout=60)
    for i in range(25):
        sc = make_scene(motion={"velocity": float(sys.argv[2]) + i, "gaps": [1e-5]})
        st.save(sc, get_model("cox-brenner").force(sc))
""")


def test_concurrent_writers_lose_nothing(tmp_path):
    path = tmp_path / "r.h5"
    procs = [subprocess.Popen([sys.executable, "-c", WRITER, str(path), str(v),
                               str(Path(__file__).parent)], env=ENV) for v in (0.5, 100.5)]
    assert [p.wait(timeout=120) for p in procs] == [0, 0]
    assert len(Store(path)) == 50


def test_two_concurrent_sweeps_on_one_store_lose_nothing(tmp_path):
    study = study_file(tmp_path, "glass-2mm-water-film",
                       'models = ["reynolds", "reynolds-finite", "lubrication"]\n[axes]\n'
                       '"motion.velocity" = {start = 0.01, stop = 1.0, points = 40}\n')
    cmd = [str(BIN / "wetcontact"), "sweep", str(study), "--store", str(tmp_path / "r.h5"),
           "--workers", "0", "--wait", "120", "--json"]
    procs = [subprocess.Popen(cmd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True) for _ in range(2)]
    outs = [json.loads(p.communicate(timeout=240)[0].splitlines()[-1]) for p in procs]
    assert [p.returncode for p in procs] == [0, 0]
    outs.sort(key=lambda o: o["computed"])  # the second waited, then reused everything
    assert [(o["computed"], o["reused"], o["failed"]) for o in outs] == [(0, 120, 0),
                                                                          (120, 0, 0)]
    assert len(Store(tmp_path / "r.h5")) == 120


def _sweep_json(args: list[str], timeout: float = 600) -> dict:
    out = subprocess.run([str(BIN / "wetcontact"), "sweep", *args, "--json"], env=ENV,
                         capture_output=True, text=True, timeout=timeout)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.splitlines()[-1])


def _check_against_direct_solve(store: Store, n: int = 2) -> None:
    """Stored Stokes curves equal a direct solve of the same scene (same code, same mesh)."""
    pts = [p for p in load_study(STOKES16).points() if p.model == "stokes"]
    for p in pts[:: len(pts) // n][:n]:
        direct = get_model("stokes").force(p.scene, preset="fast")
        assert np.allclose(store.load(p.key).force_viscous, direct.force_viscous,
                           rtol=1e-10, atol=0)


@pytest.mark.slow
def test_sigkill_mid_sweep_then_resume_then_nothing_to_do(tmp_path):
    path = tmp_path / "r.h5"
    proc = subprocess.Popen([str(BIN / "wetcontact"), "sweep", str(STOKES16), "--store",
                             str(path), "--workers", "2"], env=ENV, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:  # kill once some but not all curves are saved
            n = len(Store(path).find(model="stokes")) if path.exists() else 0
            if n >= 2:
                break
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGKILL)  # the client and its local cluster
    finally:
        proc.wait(timeout=30)
    saved = set(Store(path).keys())
    assert 2 <= len([k for k in saved if k]) < 32
    second = _sweep_json([str(STOKES16), "--store", str(path), "--workers", "2"])
    assert second["reused"] == len(saved) and second["computed"] == 32 - len(saved)
    assert second["failed"] == 0 and len(Store(path)) == 32
    third = _sweep_json([str(STOKES16), "--store", str(path)])
    assert (third["computed"], third["reused"]) == (0, 32)
    _check_against_direct_solve(Store(path))
    print(f"\nkill -9: {len(saved)}/32 saved; rerun computed {second['computed']}, reused "
          f"{second['reused']} in {second['wall_time_s']} s; third run computed "
          f"{third['computed']}, reused {third['reused']} in {third['wall_time_s']} s")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_sweep_on_a_dask_scheduler_with_two_workers(tmp_path):
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    log = open(tmp_path / "dask.log", "w")  # noqa: SIM115 - closed in finally
    procs = [subprocess.Popen([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1",
                               "--port", str(port), "--no-dashboard"], env=ENV,
                              stdout=log, stderr=log, start_new_session=True)]
    try:
        for _ in range(2):
            procs.append(subprocess.Popen(
                [str(BIN / "dask"), "worker", address, "--nthreads", "1", "--nworkers", "1",
                 "--no-dashboard", "--local-directory", str(tmp_path)], env=ENV,
                stdout=log, stderr=log, start_new_session=True))
        out = _sweep_json([str(STOKES16), "--store", str(tmp_path / "r.h5"), "--scheduler",
                           address], timeout=600)
        assert (out["computed"], out["failed"]) == (32, 0)
        print(f"\nscheduler {address}, 2 workers: {out}")
        _check_against_direct_solve(Store(tmp_path / "r.h5"))
    finally:
        for p in procs[::-1]:
            os.killpg(p.pid, signal.SIGTERM)
        for p in procs[::-1]:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=10)
        log.close()


def test_a_sweep_whose_workers_all_left_gives_up_on_the_points_left():
    """With every worker of an external scheduler killed, the sweep printed progress
    forever (a durability audit); now the points left are cancelled after a limit, with a
    reason, and the sweep ends (what was computed is already in the store)."""
    from wetcontact.sweep import watch_workers

    class NoWorkers:
        def __init__(self):
            self.cancelled = []

        def nthreads(self):
            return {}

        def cancel(self, futs):
            self.cancelled.extend(futs)

    client, lost, stop = NoWorkers(), [], threading.Event()
    t0 = time.monotonic()
    watch_workers(client, ["f1", "f2"], lost, stop, limit=0.2, poll=0.05)
    assert time.monotonic() - t0 < 10
    assert client.cancelled == ["f1", "f2"] and "no Dask worker for 0 s" in lost[0]

    class Workers(NoWorkers):
        def nthreads(self):
            return {"tcp://w": 1}

    busy, lost2 = Workers(), []
    timer = threading.Timer(0.5, stop.set)
    stop.clear()
    timer.start()
    watch_workers(busy, ["f"], lost2, stop, limit=0.1, poll=0.05)  # returns at stop
    assert not lost2 and not busy.cancelled
