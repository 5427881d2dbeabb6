"""HDF5 reference store with provenance.

One file; one group ``/curves/<key>`` per (scene, model, settings), keyed by the SHA-256 of
their canonical JSON. Datasets hold the curve's arrays; attributes hold the case and model
names, the scene, settings, diagnostics and provenance (package version, git commit,
library versions, wall time) as JSON.

Writes are atomic: a write copies the file to a temporary sibling, adds the new groups,
flushes and fsyncs it, and renames it over the original (``os.replace``). A process killed
at any moment leaves either the old or the new file, never a torn one, so every curve saved
before the kill is still readable. The cost of a write is one copy of the file, so callers
that save many curves batch them (:class:`BatchWriter`: one write every few seconds, the
interval growing with the write time so that writing stays below a tenth of the wall time).

One writer at a time: every write, and a whole sweep (:meth:`Store.writer`), holds an
exclusive ``fcntl`` lock on ``<file>.lock`` beside the store. Another process that wants
to write waits up to a timeout and then gets :class:`StoreBusyError` (one line naming the
process holding the lock). Readers need no lock: they see the old or the new file.

The content key includes :func:`code_version` (package version and a hash of the sources
that produce numbers), so a curve is never reused by another version of the code.
A point whose model failed or refused is kept under ``/failures/<key>`` with its reason,
so a rerun knows it without solving again.

A key already present with the same data (arrays equal to 1e-12 relative, allowing for
round-off between identical runs) is a no-op; with other data it is an error. The file
is created with the mode a plain ``open`` would give (0o666 less the umask).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import re
import shutil
import tempfile
import threading
import time
from collections.abc import Iterable, Iterator, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from wetcontact.errors import InputError
from wetcontact.fileio import _umask, fsync_dir, make_folder
from wetcontact.models import ForceCurve
from wetcontact.scene import Scene

_ARRAYS = ("gap", "force_viscous", "force_capillary", "error_estimate")
_JSON_ATTRS = ("scene", "settings", "diagnostics", "provenance")


class StoreConflictError(InputError):
    """A key is already in the store with different data."""


class StoreBusyError(InputError):
    """Another process holds the store's write lock (CLI exit 2)."""


# Sources whose edits can change a number: the key changes with them.
_NUMERIC_SOURCES = ("models.py", "scene.py", "solver", "reduced_models", "meshes")


@lru_cache(maxsize=1)
def code_version() -> str:
    """``<package version>+<hash>``: the version and a SHA-256 of the numeric sources.

    Computed once per process (the code a process runs is the code it imported): a run
    whose sources are edited under it keeps one version from its sweep to its report, so
    the report finds the curves the sweep stored (before, it recomputed the hash and found
    none: an IndexError in a report section).

    The hash covers ``models.py``, ``scene.py`` and the ``solver``, ``reduced_models`` and
    ``meshes`` packages (every ``.py`` file, by relative path and content). A clean tree
    at another commit may carry the same version string, and a dirty tree always does, so
    the version alone cannot tell two codes apart; edits elsewhere (the report, the CLI)
    do not invalidate the store.
    """
    from wetcontact import __version__

    return f"{__version__}+{source_hash(_NUMERIC_SOURCES)}"


def source_hash(names: tuple[str, ...]) -> str:
    """First 12 hex digits of a SHA-256 over the package's ``.py`` files under ``names``
    (files or folders relative to the package, by relative path and content)."""
    root = Path(__file__).resolve().parent
    files: list[Path] = []
    for name in names:
        p = root / name
        files += sorted(p.rglob("*.py")) if p.is_dir() else [p] if p.exists() else []
    h = hashlib.sha256()
    for f in files:
        h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:12]


def curve_key(scene: Scene, model: str, settings: dict[str, Any],
              version: str | None = None) -> str:
    """Content hash of (scene, model, settings, code version): SHA-256 of their canonical
    JSON; ``version`` defaults to :func:`code_version`."""
    blob = json.dumps({"scene": scene.to_dict(), "model": model, "settings": settings,
                       "code": version or code_version()},
                      sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:32]


# Locks held by this process, by lock-file path: (file descriptor, depth). ``flock`` locks
# belong to an open file description, so a second open in the same process would block on
# itself; nested holders share one descriptor instead.
_HELD: dict[str, list[int]] = {}


@contextlib.contextmanager
def _locked(lock_path: Path, timeout: float, what: str) -> Iterator[None]:
    key = str(lock_path.resolve())
    if key in _HELD:
        _HELD[key][1] += 1
        try:
            yield
        finally:
            _HELD[key][1] -= 1
        return
    try:
        make_folder(lock_path.parent)
        fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as exc:
        raise InputError(f"{what}: cannot create the lock file {lock_path} ({exc.strerror}); "
                         "allowed: a store in a writable folder") from None
    try:
        deadline = time.monotonic() + max(timeout, 0.0)
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    holder = os.pread(fd, 200, 0).decode(errors="replace").strip()
                    raise StoreBusyError(
                        f"{what}: the store is in use by another process ({holder or 'unknown'}"
                        f"); wait for it to finish or use another --store") from None
                time.sleep(0.05)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} since {time.strftime('%H:%M:%S')}".encode(), 0)
        _HELD[key] = [fd, 1]
        try:
            yield
        finally:
            del _HELD[key]
            with contextlib.suppress(OSError):
                os.ftruncate(fd, 0)
    finally:
        os.close(fd)  # closing the descriptor releases the lock


class Store:
    """The reference store at ``path`` (created on first write).

    Parameters
    ----------
    path
        HDF5 file, e.g. ``reports/reference.h5``.
    """

    def __init__(self, path: str | Path, lock_timeout: float = 60.0):
        path = Path(path)
        # a symlink names its target: the atomic replace writes the target (it replaced the
        # link by a plain file, and the link and its target took different locks)
        self.path = Path(os.path.realpath(path)) if path.is_symlink() else path
        self.lock_timeout = lock_timeout

    @property
    def lock_path(self) -> Path:
        """The lock file beside the store (``<file>.lock``)."""
        return self.path.with_name(self.path.name + ".lock")

    @contextlib.contextmanager
    def writer(self, timeout: float | None = None) -> Iterator[None]:
        """Hold the write lock for a block (a whole sweep): other writers wait or fail.
        On taking the lock (not when already held) it removes the temporary copies a
        killed writer left beside the store, each the size of the store.

        Parameters
        ----------
        timeout
            Seconds to wait for another writer to finish (default ``lock_timeout``); then
            :class:`StoreBusyError`.
        """
        fresh = str(self.lock_path.resolve()) not in _HELD
        with _locked(self.lock_path, self.lock_timeout if timeout is None else timeout,
                     str(self.path)):
            if fresh:
                self._remove_stale_copies()
            yield

    def check_writable(self) -> None:
        """Refuse, before any point is computed, a store this process could not write:
        a read-only file (refused by its mode, as root too), a folder that is not writable,
        a name too long for the temporary copy each write makes, or an HDF5 file that is
        not a store. A writer holding the lock calls it."""
        name_max = 255
        with contextlib.suppress(OSError, ValueError):
            name_max = os.pathconf(self.path.parent if self.path.parent.exists() else "/",
                                   "PC_NAME_MAX")
        if len(self.path.name) + len(".XXXXXXXX.tmp") > name_max:
            raise InputError(f"{self.path}: the store's name ({len(self.path.name)} "
                             f"characters) leaves no room for its temporary copy; allowed: "
                             f"at most {name_max - len('.XXXXXXXX.tmp')} characters")
        if self.path.parent.exists() and not os.access(self.path.parent, os.W_OK):
            raise InputError(f"{self.path}: its folder is not writable; allowed: a store in "
                             "a folder you can write to")
        if self.path.is_file():
            mode = os.stat(self.path).st_mode
            if not mode & 0o200:
                raise InputError(f"{self.path}: the store file is read-only (mode "
                                 f"{mode & 0o777:o}); allowed: a writable store (chmod u+w) "
                                 "or another --store")
            with self._open():  # a damaged or foreign file: exit 2 before any work
                pass

    def _remove_stale_copies(self) -> None:
        if not self.path.parent.is_dir():
            return
        pat = re.compile(re.escape(self.path.name) + r"\.[A-Za-z0-9_]{8}\.tmp")
        for p in self.path.parent.iterdir():
            if pat.fullmatch(p.name) and p.is_file():
                with contextlib.suppress(OSError):
                    p.unlink()

    # ---- reading --------------------------------------------------------------------
    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File | None]:
        if not self.path.exists():
            yield None
            return
        if self.path.is_dir():
            raise InputError(f"{self.path}: a folder; allowed: an HDF5 store file (e.g. "
                             f"{self.path / 'reference.h5'})")
        try:
            f = h5py.File(self.path, "r")
        except OSError as exc:
            raise InputError(f"{self.path}: not a readable HDF5 store ({exc})") from None
        with f:
            for name in ("curves", "failures"):
                if name in f and not isinstance(f[name], h5py.Group):
                    raise InputError(f"{self.path}: not a wetcontact store ('{name}' is a "
                                     f"{type(f[name]).__name__}, not a group); allowed: a "
                                     "store written by wetcontact, or a new file")
            yield f

    def _curve(self, grp: h5py.Group, key: str) -> ForceCurve:
        try:
            return _read_curve(grp)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{self.path}: curve {key} is damaged ({type(exc).__name__}: "
                             f"{exc}); allowed: a curve written by wetcontact (remove it, "
                             "or sweep into a new store)") from None

    def keys(self) -> list[str]:
        """All keys in the store."""
        with self._open() as f:
            return [] if f is None or "curves" not in f else sorted(f["curves"])

    def __contains__(self, key: str) -> bool:
        with self._open() as f:
            return f is not None and "curves" in f and key in f["curves"]

    def failures(self) -> dict[str, str]:
        """Keys of points whose model failed or refused, with the reason."""
        with self._open() as f:
            if f is None or "failures" not in f:
                return {}
            return {k: str(g.attrs["reason"]) for k, g in f["failures"].items()}

    def __len__(self) -> int:
        return len(self.keys())

    def load(self, key: str) -> ForceCurve:
        """The curve stored under ``key``."""
        with self._open() as f:
            if f is None or key not in f.get("curves", {}):
                raise KeyError(f"{self.path}: no curve with key {key}")
            return self._curve(f["curves"][key], key)

    def find(self, case: str | None = None, model: str | None = None) -> list[str]:
        """Keys whose case and/or model name match."""
        out = []
        with self._open() as f:
            if f is None or "curves" not in f:
                return []
            for key, grp in f["curves"].items():
                if (case is None or grp.attrs["case"] == case) and (
                    model is None or grp.attrs["model"] == model
                ):
                    out.append(key)
        return sorted(out)

    def load_many(self, keys: Iterable[str]) -> dict[str, ForceCurve]:
        """The curves stored under ``keys`` (missing keys are left out), one file open."""
        with self._open() as f:
            if f is None or "curves" not in f:
                return {}
            grp = f["curves"]
            return {k: self._curve(grp[k], k) for k in keys if k in grp}

    def get(self, scene: Scene, curve_or_model: ForceCurve | str,
            settings: dict[str, Any] | None = None) -> ForceCurve | None:
        """The stored curve for (scene, model, settings), or ``None``.

        With a model name, ``settings`` are the options given to ``force`` (the preset
        under ``"preset"``, default ``"default"``): the key uses the settings the curve
        carries, ``Model.settings_for``, as a saved curve does."""
        if isinstance(curve_or_model, ForceCurve):
            key = curve_key(scene, curve_or_model.model, dict(curve_or_model.settings))
        else:
            from wetcontact.models import get_model

            opts = dict(settings or {})
            full = get_model(curve_or_model).settings_for(opts.pop("preset", "default"),
                                                          **opts)
            key = curve_key(scene, curve_or_model, full)
        return self.load(key) if key in self else None

    # ---- writing --------------------------------------------------------------------
    def save(self, scene: Scene, curve: ForceCurve) -> str:
        """Save one curve atomically; return its key."""
        return self.save_many([(scene, curve)])[0]

    def save_many(self, items: Iterable[tuple[Scene, ForceCurve]],
                  failures: Iterable[tuple[str, Scene, str, dict[str, Any], str]] = (),
                  keys: Sequence[str] | None = None) -> list[str]:
        """Save several curves (and failure records) in one atomic write; return the keys.

        Parameters
        ----------
        items
            ``(scene, curve)`` pairs.
        failures
            ``(key, scene, model, settings, reason)`` of points that failed or were refused;
            a failure record never replaces a curve, and a curve replaces its failure record.
        keys
            The items' keys when the caller knows them (a sweep's ``Point.key``, made from
            the same scene, model and settings); computed from each curve otherwise.
        """
        items = list(items)
        failures = list(failures)
        for sc, cv in items:  # a curve is stored under its own scene only
            if cv.case != sc.name or not np.array_equal(cv.gap, sc.gap_array):
                raise InputError(f"store {self.path}: curve of '{cv.case}' by '{cv.model}' "
                                 f"({cv.gap.size} gaps) saved under scene '{sc.name}' "
                                 f"({len(sc.gaps)} gaps); allowed: the scene it was "
                                 "computed for, on the same gaps")
        keys = list(keys) if keys is not None else [
            curve_key(sc, cv.model, dict(cv.settings)) for sc, cv in items]
        if len(keys) != len(items):
            raise ValueError("save_many: one key per item")
        if not items and not failures:
            return keys
        make_folder(self.path.parent)
        with self.writer():
            self._write(keys, items, failures)
        return keys

    def _write(self, keys: list[str], items: list[tuple[Scene, ForceCurve]],
               failures: list[tuple[str, Scene, str, dict[str, Any], str]]) -> None:
        fd, tmp = tempfile.mkstemp(prefix=self.path.name + ".", suffix=".tmp",
                                   dir=self.path.parent)
        os.close(fd)
        try:
            if self.path.exists():
                shutil.copyfile(self.path, tmp)
                mode, perm = "a", os.stat(self.path).st_mode & 0o777
            else:
                mode, perm = "w", 0o666 & ~_umask()
            with h5py.File(tmp, mode) as f:
                grp = f.require_group("curves")
                changed = False
                for key, (sc, cv) in zip(keys, items, strict=True):
                    if key in grp:
                        _check_same(self.path, key, grp[key], cv)
                        continue
                    _write_curve(grp.create_group(key), sc, cv)
                    if "failures" in f and key in f["failures"]:
                        del f["failures"][key]
                    changed = True
                fgrp = f.require_group("failures") if failures else None
                for key, sc, model, settings, reason in failures:
                    if key in grp or key in fgrp:
                        continue
                    g = fgrp.create_group(key)
                    g.attrs.update(case=sc.name, model=model, scene=sc.canonical_json(),
                                   settings=json.dumps(settings, sort_keys=True, default=str),
                                   reason=reason, code_version=code_version())
                    changed = True
                f.flush()
            if not changed:
                os.unlink(tmp)
                return
            os.chmod(tmp, perm)
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
            os.replace(tmp, self.path)
            fsync_dir(self.path.parent)
        except BaseException as exc:
            full = full_disk_error(exc, self.path)  # before the copy's space is freed
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            if full is not None:
                raise full from exc
            raise


#: free space (bytes) below which a write error of HDF5 is taken for a full disk
LOW_SPACE = 16 * 2**20
_FULL = (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))


def full_disk_error(exc: BaseException, path: Path) -> OSError | None:
    """The full-disk ``OSError`` (ENOSPC or EDQUOT) naming the store ``path`` that a failed
    write stands for, or ``None`` when it is another error.

    A full disk reaches a writer in several forms: an ``OSError`` with its errno (from
    the copy, or from h5py naming the hidden temporary), an HDF5 error whose text holds
    ``errno = 28``, or, once a failed write has left HDF5's state inconsistent, an error
    that says nothing of the disk (``RuntimeError: Slist already enabled?``). The last is
    taken for a full disk when the store's folder has less than :data:`LOW_SPACE` (or the
    store's size) free, so the user sees the one ENOSPC line of the CLI (exit 2) instead
    of an internal error.
    """
    if isinstance(exc, OSError) and exc.errno in _FULL:
        return OSError(exc.errno, os.strerror(exc.errno), str(path))
    if not isinstance(exc, OSError | RuntimeError):  # what h5py raises
        return None
    text = str(exc)
    for code in _FULL:
        if os.strerror(code) in text or f"errno = {code}," in text:
            return OSError(code, os.strerror(code), str(path))
    try:
        st = os.statvfs(path.parent)
        size = path.stat().st_size if path.is_file() else 0
    except OSError:
        return None
    free = (st.f_bfree if os.geteuid() == 0 else st.f_bavail) * st.f_frsize
    if free >= max(LOW_SPACE, size):
        return None
    what = " ".join(text.split())[:80]
    return OSError(errno.ENOSPC, f"{os.strerror(errno.ENOSPC)} ({free} bytes free; HDF5: "
                   f"{type(exc).__name__}: {what})", str(path))


class BatchWriter:
    """Collects curves and failure records and saves them in batches.

    A batch is written when :meth:`maybe_flush` finds the last write older than the
    interval, ``max(min_interval, 10 x the last write's duration)``, so that copying a
    large file stays a small part of the wall time, or when ``max_batch`` curves are
    pending (results arriving faster than they can be written must not pile up into one
    huge write). :meth:`flush` writes whatever is pending. Whatever was flushed survives
    a SIGKILL; what is pending is lost and recomputed by the next run.
    """

    def __init__(self, store: Store, min_interval: float = 2.0, max_batch: int = 2000):
        self.store = store
        self.min_interval = min_interval
        self.max_batch = max_batch
        self.pending: list[tuple[Scene, ForceCurve]] = []
        self.pending_keys: list[str | None] = []
        self.pending_failures: list[tuple[str, Scene, str, dict[str, Any], str]] = []
        self.last = time.monotonic()
        self.interval = min_interval
        self.written = 0
        self.write_time = 0.0
        self.writes = 0
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._error: BaseException | None = None

    def add(self, scene: Scene, curve: ForceCurve, key: str | None = None) -> None:
        """Queue one curve (with its key if known)."""
        with self._lock:
            self._raise_background_error()
            self.pending.append((scene, curve))
            self.pending_keys.append(key or curve_key(scene, curve.model,
                                                      dict(curve.settings)))

    def add_failure(self, key: str, scene: Scene, model: str, settings: dict[str, Any],
                    reason: str) -> None:
        """Queue one failure record."""
        with self._lock:
            self._raise_background_error()
            self.pending_failures.append((key, scene, model, settings, reason))

    def maybe_flush(self) -> None:
        """Write the pending batch if the interval has passed or it holds ``max_batch``
        curves (a cap on what a SIGKILL can lose and on the client's memory)."""
        with self._lock:
            if (time.monotonic() - self.last >= self.interval
                    or len(self.pending) + len(self.pending_failures) >= self.max_batch):
                self.flush()

    @contextlib.contextmanager
    def background(self, poll: float = 0.5) -> Iterator[None]:
        """While the block runs, a thread writes what is pending once the interval has
        passed, without waiting for the next result: a finished point is then in the
        store within about the interval even while the next one takes minutes (an audit
        lost a 40 s Stokes point to a SIGKILL because the sweep waited for the next
        result to write it). A write error in the thread is raised in the caller's next
        :meth:`add` or :meth:`flush`."""
        def loop() -> None:
            while not self._stop.wait(poll):
                with self._lock:
                    if (self._error is None and (self.pending or self.pending_failures)
                            and time.monotonic() - self.last >= self.interval):
                        try:
                            self.flush()
                        except BaseException as exc:  # noqa: BLE001 - handed to the caller
                            self._error = exc

        self._stop.clear()
        thread = threading.Thread(target=loop, name="wetcontact-store-writer", daemon=True)
        thread.start()
        try:
            yield
        finally:
            self._stop.set()
            thread.join()

    def _raise_background_error(self) -> None:
        if self._error is not None:
            err, self._error = self._error, None
            raise err

    def flush(self) -> None:
        """Write every pending curve and failure record in one atomic write."""
        with self._lock:
            self._raise_background_error()
            self._flush()

    def _flush(self) -> None:
        if self.pending or self.pending_failures:
            t0 = time.monotonic()
            self.store.save_many(self.pending, self.pending_failures, self.pending_keys)
            dt = time.monotonic() - t0
            self.written += len(self.pending)
            self.write_time += dt
            self.writes += 1
            self.interval = max(self.min_interval, 10.0 * dt)
            self.pending, self.pending_failures, self.pending_keys = [], [], []
        self.last = time.monotonic()


def _write_curve(grp: h5py.Group, scene: Scene, curve: ForceCurve) -> None:
    grp.attrs["case"] = curve.case
    grp.attrs["model"] = curve.model
    grp.attrs["scene"] = scene.canonical_json()
    grp.attrs["settings"] = json.dumps(dict(curve.settings), sort_keys=True, default=str)
    grp.attrs["diagnostics"] = json.dumps(
        {k: (v.tolist() if isinstance(v, np.ndarray) else v)
         for k, v in curve.diagnostics.items()}, sort_keys=True, default=str)
    grp.attrs["provenance"] = json.dumps(dict(curve.provenance), sort_keys=True, default=str)
    grp.attrs["wall_time_s"] = float(curve.diagnostics.get("wall_time_s", 0.0))
    grp.attrs["code_version"] = code_version()
    for name in _ARRAYS:
        val = getattr(curve, name)
        if val is not None:
            grp.create_dataset(name, data=np.asarray(val))
    ex = grp.create_group("extras")
    for name, val in curve.extras.items():
        ex.create_dataset(name, data=np.asarray(val))


def _read_curve(grp: h5py.Group) -> ForceCurve:
    arrays = {n: (grp[n][()] if n in grp else None) for n in _ARRAYS}
    return ForceCurve(
        case=str(grp.attrs["case"]), model=str(grp.attrs["model"]), gap=arrays["gap"],
        force_viscous=arrays["force_viscous"], force_capillary=arrays["force_capillary"],
        error_estimate=arrays["error_estimate"],
        extras={k: v[()] for k, v in grp["extras"].items()},
        settings=json.loads(grp.attrs["settings"]),
        diagnostics=json.loads(grp.attrs["diagnostics"]),
        provenance=json.loads(grp.attrs["provenance"]),
    )


def _check_same(path: Path, key: str, grp: h5py.Group, curve: ForceCurve) -> None:
    old = _read_curve(grp)
    for name in _ARRAYS:
        a, b = getattr(old, name), getattr(curve, name)
        if (a is None) != (b is None) or (
            a is not None and (a.shape != b.shape or not np.allclose(a, b, rtol=1e-12, atol=0))
        ):
            raise StoreConflictError(
                f"{path}: key {key} ({curve.case}, {curve.model}) already holds other "
                f"{name}; delete it or change the settings")
    if set(old.extras) != set(curve.extras):
        raise StoreConflictError(f"{path}: key {key} holds other extras")
