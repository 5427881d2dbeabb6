"""HDF5 reference store with provenance.

One file; one group ``/curves/<key>`` per (scene, model, settings), keyed by the SHA-256 of
their canonical JSON. Datasets hold the curve's arrays; attributes hold the case and model
names, the scene, settings, diagnostics and provenance (package version, git commit,
library versions, wall time) as JSON.

Writes are atomic: a write copies the file to a temporary sibling, adds the new groups,
flushes and fsyncs it, and renames it over the original (``os.replace``). A process killed
at any moment leaves either the old or the new file, never a torn one, so every curve saved
before the kill is still readable. Only one process writes (the sweep's client).

A key already present with the same data (arrays equal to 1e-12 relative, allowing for
round-off between identical runs) is a no-op; with other data it is an error.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from wetcontact.errors import InputError
from wetcontact.models import ForceCurve
from wetcontact.scene import Scene

_ARRAYS = ("gap", "force_viscous", "force_capillary", "error_estimate")
_JSON_ATTRS = ("scene", "settings", "diagnostics", "provenance")


class StoreConflictError(InputError):
    """A key is already in the store with different data."""


def curve_key(scene: Scene, model: str, settings: dict[str, Any]) -> str:
    """Content hash of (scene, model, settings): SHA-256 of their canonical JSON."""
    blob = json.dumps({"scene": scene.to_dict(), "model": model, "settings": settings},
                      sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:32]


class Store:
    """The reference store at ``path`` (created on first write).

    Parameters
    ----------
    path
        HDF5 file, e.g. ``reports/reference.h5``.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)

    # ---- reading --------------------------------------------------------------------
    @contextlib.contextmanager
    def _open(self) -> Iterator[h5py.File | None]:
        if not self.path.exists():
            yield None
            return
        try:
            f = h5py.File(self.path, "r")
        except OSError as exc:
            raise InputError(f"{self.path}: not a readable HDF5 store ({exc})") from None
        with f:
            yield f

    def keys(self) -> list[str]:
        """All keys in the store."""
        with self._open() as f:
            return [] if f is None or "curves" not in f else sorted(f["curves"])

    def __contains__(self, key: str) -> bool:
        return key in self.keys()

    def __len__(self) -> int:
        return len(self.keys())

    def load(self, key: str) -> ForceCurve:
        """The curve stored under ``key``."""
        with self._open() as f:
            if f is None or key not in f.get("curves", {}):
                raise KeyError(f"{self.path}: no curve with key {key}")
            return _read_curve(f["curves"][key])

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

    def get(self, scene: Scene, curve_or_model: ForceCurve | str,
            settings: dict[str, Any] | None = None) -> ForceCurve | None:
        """The stored curve for (scene, model, settings), or ``None``."""
        if isinstance(curve_or_model, ForceCurve):
            key = curve_key(scene, curve_or_model.model, dict(curve_or_model.settings))
        else:
            key = curve_key(scene, curve_or_model, settings or {})
        return self.load(key) if key in self else None

    # ---- writing --------------------------------------------------------------------
    def save(self, scene: Scene, curve: ForceCurve) -> str:
        """Save one curve atomically; return its key."""
        return self.save_many([(scene, curve)])[0]

    def save_many(self, items: Iterable[tuple[Scene, ForceCurve]]) -> list[str]:
        """Save several curves in one atomic write; return their keys."""
        items = list(items)
        keys = [curve_key(sc, cv.model, dict(cv.settings)) for sc, cv in items]
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=self.path.name + ".", suffix=".tmp",
                                   dir=self.path.parent)
        os.close(fd)
        try:
            if self.path.exists():
                shutil.copyfile(self.path, tmp)
                mode = "a"
            else:
                mode = "w"
            with h5py.File(tmp, mode) as f:
                grp = f.require_group("curves")
                changed = False
                for key, (sc, cv) in zip(keys, items, strict=True):
                    if key in grp:
                        _check_same(self.path, key, grp[key], cv)
                        continue
                    _write_curve(grp.create_group(key), sc, cv)
                    changed = True
                f.flush()
            if not changed:
                os.unlink(tmp)
                return keys
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
            os.replace(tmp, self.path)
            _fsync_dir(self.path.parent)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise
        return keys


def _fsync_dir(path: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


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
