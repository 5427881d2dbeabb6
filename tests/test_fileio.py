"""Safe file stems and atomic writes under faults (issue 14): an injected full disk
(``OSError(ENOSPC)``), a real full disk (a 64 kB tmpfs, where mounting is allowed) and a
writer killed with SIGKILL. Afterwards every file in the output folder is the old complete
version or the new complete version; no zero-byte files; the CLI says so in one line."""

from __future__ import annotations

import contextlib
import errno
import io
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import pytest
from conftest import IMMERSED_TOML
from hypothesis import given, settings
from hypothesis import strategies as st

from wetcontact import cli, fileio
from wetcontact.errors import InputError
from wetcontact.fileio import MAX_STEM, atomic_output, atomic_write_text, safe_stem

ROOT = Path(__file__).resolve().parents[1]
TEMP = re.compile(r"^\..*\.tmp(\.\w+)?$")  # atomic writers' temporaries (hidden)


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(argv)
    return code, out.getvalue(), err.getvalue()


def visible(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if not TEMP.match(p.name)}


# ---- safe_stem -------------------------------------------------------------------------


@settings(max_examples=300, derandomize=True)
@given(name=st.text(st.characters(exclude_categories=("Cs",)), max_size=300)
       | st.sampled_from(["..", ".", "../../x", "/etc/passwd", "a/../../b", "x" * 5000,
                          "C:\\Windows", "\x00", "-rf", ".hidden"]))
def test_safe_stem_is_one_harmless_path_component(tmp_path_factory, name):
    stem = safe_stem(name)
    assert re.fullmatch(r"[A-Za-z0-9_-][A-Za-z0-9._-]*", stem), stem
    assert len(stem) <= MAX_STEM and stem not in (".", "..")
    folder = Path("/base/folder")
    assert (folder / f"{stem}.vtu").parent == folder
    assert os.path.normpath(folder / stem).startswith(str(folder) + os.sep)


@settings(max_examples=300, derandomize=True)
@given(a=st.text(max_size=120), b=st.text(max_size=120))
def test_safe_stem_keeps_different_names_apart(a, b):
    if a != b:
        assert safe_stem(a) != safe_stem(b)
    else:
        assert safe_stem(a) == safe_stem(b)


def test_safe_stem_leaves_plain_names_alone():
    assert safe_stem("glass-2mm-water-film") == "glass-2mm-water-film"
    assert safe_stem("../../x").startswith("_.._x-")


# ---- atomic_write_text and atomic_output ------------------------------------------------


def test_atomic_write_text_replaces_and_uses_the_umask(tmp_path):
    target = tmp_path / "r.md"
    atomic_write_text(target, "old\n")
    atomic_write_text(target, "new\n")
    assert target.read_text() == "new\n"
    mask = os.umask(0)
    os.umask(mask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~mask
    assert [p.name for p in tmp_path.iterdir()] == ["r.md"]


def test_a_special_file_as_output_is_refused_not_replaced(tmp_path):
    """Renaming over a pipe (or, as root, over /dev/null) would replace the special file
    itself with a regular one: the writers refuse it, and it stays what it was."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    for write in (lambda: atomic_write_text(fifo, "x"),
                  lambda: atomic_output(fifo).__enter__()):
        with pytest.raises(InputError, match="pipe.*not a regular file.*allowed: a regular "
                                             "file or a new path"):
            write()
        assert fifo.is_fifo()
    assert [p.name for p in tmp_path.iterdir()] == ["pipe"]  # no temporary left


def test_path_errors_name_the_output_not_the_temporary(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    with pytest.raises(IsADirectoryError) as info:
        atomic_write_text(folder, "x")
    assert (info.value.filename, info.value.filename2) == (str(folder), None)
    missing = tmp_path / "no" / "r.csv"
    with pytest.raises(FileNotFoundError) as info:
        atomic_write_text(missing, "x")
    assert (info.value.filename, info.value.filename2) == (str(missing), None)
    a_file = tmp_path / "f"
    a_file.write_text("")
    with pytest.raises(NotADirectoryError) as info:
        atomic_write_text(a_file / "r.csv", "x")
    assert info.value.filename == str(a_file / "r.csv")
    with pytest.raises(NotADirectoryError) as info:  # not "File exists"
        fileio.make_folder(a_file / "sub" / "deeper")
    assert info.value.filename == str(a_file)
    fileio.make_folder(tmp_path / "new" / "deeper")
    assert (tmp_path / "new" / "deeper").is_dir()


def test_cli_refuses_a_pipe_as_output_with_exit_2(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    code, _, err = run_cli(["export", "json", "--closure", "calibrated-viscous", "--out",
                            str(fifo)])
    assert code == 2 and "Traceback" not in err
    assert f"{str(fifo)!r}: exists and is not a regular file" in err
    assert fifo.is_fifo()
    code, _, err = run_cli(["export", "json", "--closure", "calibrated-viscous", "--out",
                            str(tmp_path)])
    assert code == 2 and err.count(str(tmp_path)) == 1 and "give a file, not a folder" in err


@pytest.mark.parametrize("where", ["write", "fsync", "replace"])
def test_injected_enospc_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch, where):
    target = tmp_path / "README.md"
    atomic_write_text(target, "old complete\n")
    full = OSError(errno.ENOSPC, "No space left on device")

    if where == "write":
        real = os.fdopen

        def fdopen(fd, *a, **k):
            fh = real(fd, *a, **k)
            orig = fh.write

            def write(text):
                orig(text[: len(text) // 2])
                fh.flush()
                raise full
            fh.write = write
            return fh
        monkeypatch.setattr(fileio.os, "fdopen", fdopen)
    else:
        def boom(*a, **k):
            raise full
        monkeypatch.setattr(fileio.os, where, boom)
    with pytest.raises(OSError) as info:
        atomic_write_text(target, "new complete\n" * 1000)
    assert info.value.errno == errno.ENOSPC
    monkeypatch.undo()
    assert visible(tmp_path) == {"README.md": b"old complete\n"}
    assert list(tmp_path.iterdir()) == [target]  # the temporary is gone too


def test_atomic_output_for_writers_that_want_a_name(tmp_path):
    target = tmp_path / "f.vtu"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_output(target) as tmp:
        assert tmp.suffix == ".vtu" and tmp.parent == tmp_path
        tmp.write_text("partial")
        raise RuntimeError("writer died")
    assert visible(tmp_path) == {"f.vtu": b"old"} and len(list(tmp_path.iterdir())) == 1
    with atomic_output(target) as tmp:
        tmp.write_text("new")
    assert visible(tmp_path) == {"f.vtu": b"new"} and len(list(tmp_path.iterdir())) == 1


_WRITER = """
import sys
from wetcontact.fileio import atomic_write_text
i = 0
while True:
    i += 1
    atomic_write_text(sys.argv[1], (f"version {i} " + "x" * 4_000_000 + " end\\n"))
"""


@pytest.mark.parametrize("delay", [0.05, 0.2, 0.5])
def test_killed_writer_leaves_a_complete_file(tmp_path, delay):
    target = tmp_path / "curve.csv"
    atomic_write_text(target, "version 0 old end\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.Popen([sys.executable, "-c", _WRITER, str(target)], env=env)
    time.sleep(delay + 0.3)  # past the interpreter start, inside some write
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    text = target.read_text()
    assert text.startswith("version ") and text.endswith(" end\n")
    assert text == "version 0 old end\n" or len(text) > 4_000_000
    for p in tmp_path.iterdir():  # a killed writer may leave its hidden temporary, only that
        assert p == target or TEMP.match(p.name), p.name
    assert target.stat().st_size > 0


# ---- solve --save-fields under faults ------------------------------------------------


def _case(tmp_path: Path, gaps: str = "[1.0e-4]") -> Path:
    p = tmp_path / "imm.toml"
    p.write_text(IMMERSED_TOML.format(gaps=gaps))
    return p


def _complete_vtu(path: Path) -> bool:
    try:
        mesh = meshio.read(path)
    except (Exception, SystemExit):  # noqa: BLE001 - meshio exits on a truncated file
        return False
    return mesh.points.shape[0] > 0 and "pressure" in mesh.point_data


def test_save_fields_on_a_full_disk_keeps_old_files_and_says_so(tmp_path, monkeypatch):
    case, out = _case(tmp_path, "[1.0e-4, 2.0e-4]"), tmp_path / "fields"
    code, _, err = run_cli(["solve", str(case), "--model", "stokes", "--preset", "fast",
                            "--save-fields", str(out)])
    assert code == 0, err
    old = visible(out)
    assert len(old) == 3 and all(len(b) > 0 for b in old.values())  # 2 VTU, the .pvd
    real = meshio.Mesh.write
    calls = []

    def write(self, path, *a, **k):  # the second file hits a full disk half-way
        calls.append(path)
        if len(calls) == 2:
            Path(path).write_bytes(b"<VTKFile partial")
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real(self, path, *a, **k)

    monkeypatch.setattr(meshio.Mesh, "write", write)
    case.write_text(IMMERSED_TOML.format(gaps="[1.0e-4, 2.0e-4]").replace("0.1\n", "0.2\n"))
    code, stdout, err = run_cli(["solve", str(case), "--model", "stokes", "--preset", "fast",
                                 "--save-fields", str(out)])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "No space left on device" in err and "free some space" in err
    now = visible(out)
    assert set(now) == set(old) and len(list(out.iterdir())) == 3  # no temporaries
    names = sorted(now)
    assert now[names[0]] != old[names[0]] and _complete_vtu(out / names[0])  # new, complete
    assert now[names[1]] == old[names[1]]  # old, complete
    assert names[2].endswith(".pvd") and now[names[2]] == old[names[2]]  # not rewritten


def test_killed_solve_save_fields_leaves_only_complete_files(tmp_path):
    case, out = _case(tmp_path, "{ start = 1e-4, stop = 1e-1, points = 30 }"), tmp_path / "f"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.Popen([sys.executable, "-m", "wetcontact.cli", "solve", str(case),
                             "--model", "stokes", "--preset", "fast", "--save-fields",
                             str(out)], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120 and not (out.is_dir() and len(list(out.iterdir())) > 3):
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    files = [p for p in out.iterdir() if not TEMP.match(p.name)]
    assert len(files) >= 3
    for p in files:
        assert p.stat().st_size > 0 and _complete_vtu(p), p.name


# ---- a real full disk: a 64 kB tmpfs --------------------------------------------------


@pytest.fixture
def tiny_disk(tmp_path):
    mnt = tmp_path / "tiny"
    mnt.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
                       capture_output=True)
    if r.returncode != 0:
        pytest.skip("mounting a tmpfs is not permitted here")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


def test_tmpfs_full_disk_atomic_write(tiny_disk):
    target = tiny_disk / "README.md"
    atomic_write_text(target, "old complete\n")
    with pytest.raises(OSError) as info:
        atomic_write_text(target, "y" * 200_000)
    assert info.value.errno == errno.ENOSPC
    assert visible(tiny_disk) == {"README.md": b"old complete\n"}
    assert len(list(tiny_disk.iterdir())) == 1


def test_tmpfs_full_disk_save_fields(tmp_path, tiny_disk):
    case = _case(tmp_path, "[1.0e-4, 2.0e-4, 4.0e-4]")
    filler = tiny_disk / "filler"
    filler.write_bytes(b"z" * 20_000)
    code, out, err = run_cli(["solve", str(case), "--model", "stokes", "--preset", "fast",
                              "--save-fields", str(tiny_disk)])
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "No space left on device" in err
    for p in tiny_disk.iterdir():
        assert not TEMP.match(p.name), p.name
        assert p == filler or _complete_vtu(p), p.name
    assert filler.read_bytes() == b"z" * 20_000
