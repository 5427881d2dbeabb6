"""Mesh cache: gmsh meshes stored as ``.msh`` files keyed by a hash of their parameters.

The key is the SHA-256 of the canonical JSON of (builder name, parameters, resolution,
:data:`MESH_VERSION`, gmsh version). The directory is, in order: the ``cache_dir`` argument,
the environment variable ``WETCONTACT_CACHE`` (its ``meshes`` subdirectory), or
``~/.cache/wetcontact/meshes``. Files are written atomically (temporary file + rename), so
concurrent processes at worst build the same mesh twice. Within a process the converted
scikit-fem meshes are also kept in a small LRU memo.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import tempfile
from collections import OrderedDict
from pathlib import Path
from typing import Any

import meshio
import numpy as np
from skfem import MeshTri2

from wetcontact.errors import InputError
from wetcontact.meshes import builders
from wetcontact.meshes.io import read_msh, to_skfem

MESH_VERSION = 6
"""Bump when a builder changes the mesh it produces for the same parameters."""

BUILDERS = {
    "sphere_wall": builders.sphere_wall,
    "sphere_sphere": builders.sphere_sphere,
    "isolated_sphere": builders.isolated_sphere,
    "sphere_film": builders.sphere_film,
    "sphere_bridge": builders.sphere_bridge,
}

_MEMO: OrderedDict[str, MeshTri2] = OrderedDict()
_MEMO_SIZE = 8


def cache_dir(cache_dir: str | Path | None = None) -> Path:
    """The mesh cache directory (created on demand)."""
    if cache_dir is not None:
        return Path(cache_dir)
    env = os.environ.get("WETCONTACT_CACHE")
    if env:
        return Path(env) / "meshes"
    return Path.home() / ".cache" / "wetcontact" / "meshes"


def _canonical(v: Any) -> Any:
    if dataclasses.is_dataclass(v):
        return {k: _canonical(x) for k, x in sorted(dataclasses.asdict(v).items())}
    if isinstance(v, np.ndarray):
        return [_canonical(x) for x in v.tolist()]
    if isinstance(v, list | tuple):
        return [_canonical(x) for x in v]
    if isinstance(v, float):
        return repr(v)
    return v


def mesh_key(builder: str, **params: Any) -> str:
    """Content hash of a mesh request."""
    import gmsh

    doc = {"builder": builder, "params": {k: _canonical(v) for k, v in sorted(params.items())},
           "version": MESH_VERSION, "gmsh": gmsh.__version__}
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:24]


def get_meshio(builder: str, cache: str | Path | None = None,
               **params: Any) -> tuple[meshio.Mesh, bool]:
    """The meshio mesh for ``builder(**params)``, from the cache when present.

    Returns
    -------
    mesh, hit
        The mesh, and whether it came from the cache.
    """
    if builder not in BUILDERS:
        raise InputError(f"mesh builder = {builder!r}; allowed: " + ", ".join(BUILDERS))
    d = cache_dir(cache)
    path = d / f"{builder}-{mesh_key(builder, **params)}.msh"
    if path.exists():
        try:
            return read_msh(path), True
        except Exception:  # a corrupt cache file is rebuilt, not trusted
            path.unlink(missing_ok=True)
    m = BUILDERS[builder](**params)
    d.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".msh", dir=d)
    os.close(fd)
    try:
        meshio.write(tmp, m, file_format="gmsh", binary=True)
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return m, False


def get_mesh(builder: str, cache: str | Path | None = None, **params: Any) -> MeshTri2:
    """The scikit-fem mesh (named boundaries) for ``builder(**params)``, cached."""
    key = f"{cache_dir(cache)}:{builder}:{mesh_key(builder, **params)}"
    if key in _MEMO:
        _MEMO.move_to_end(key)
        return _MEMO[key]
    m, _ = get_meshio(builder, cache=cache, **params)
    mesh = to_skfem(m)
    _MEMO[key] = mesh
    while len(_MEMO) > _MEMO_SIZE:
        _MEMO.popitem(last=False)
    return mesh


def clear_memo() -> None:
    """Forget the in-process meshes (the files stay)."""
    _MEMO.clear()
