"""Solved ``meniscus`` branches kept in the user cache, so that work that is killed or fails
loses nothing already computed: the calibrated-capillary generator's tensor nodes and
held-out bridges, and the rupture distances a study's gaps are scaled by."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np


def cache_file(prefix: str, sources: Sequence[str], folder: Path | None = None) -> Path:
    """``<folder>/<prefix>-<hash>.jsonl``: one file per version of ``sources`` (paths under
    the package, hashed by :func:`wetcontact.store.source_hash`); ``folder`` defaults to
    ``$XDG_CACHE_HOME/wetcontact`` (``~/.cache/wetcontact``)."""
    from wetcontact.store import source_hash

    if folder is None:
        folder = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "wetcontact"
    return folder / f"{prefix}-{source_hash(tuple(sources))}.jsonl"


def read_rows(path: Path) -> Iterator[dict[str, Any]]:
    """The JSON objects of a JSON-lines file, one per line; a line a kill cut short (not
    JSON, or without a ``key``) is skipped; no file: none."""
    if not path.is_file():
        return
    for line in path.read_text().splitlines():
        try:
            row = json.loads(line)
        except ValueError:
            continue
        if isinstance(row, dict) and "key" in row:
            yield row


def append_row(path: Path, row: dict[str, Any]) -> None:
    """Append ``row`` as one JSON line (a read-only cache costs a rerun, not the work)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("a") as fh:
            fh.write(json.dumps(row) + "\n")
    except OSError:
        pass


class NodeCache:
    """Solved branches (the generator's tensor nodes, the split angle's bisection steps and the
    held-out bridges; a study's rupture distances), appended one JSON line each as they
    arrive, so that a generation that is killed or fails loses nothing already computed:
    a rerun reuses them. One file per version of the sources the branches depend on
    (:data:`NODE_SOURCES`, hashed by :func:`wetcontact.store.source_hash`; editing the
    closure's own evaluation does not invalidate it) in ``$XDG_CACHE_HOME/wetcontact``
    (``~/.cache/wetcontact``). ``prefix`` names the file (studies keep their bridges'
    rupture distances in ``study_rupture``)."""

    def __init__(self, folder: Path | None = None, prefix: str = "calibrated_capillary"):
        self.path = cache_file(prefix, NODE_SOURCES, folder)
        self.rows: dict[str, tuple[float, list[float]]] = {}
        for row in read_rows(self.path):
            if "s_c" in row and "q" in row:
                self.rows[row["key"]] = (row["s_c"], row["q"])

    @staticmethod
    def key(job: tuple) -> str:
        _idx, kind, ratio, v, theta, c_nodes, theta2 = job
        other = "" if theta2 is None else f"|{theta2!r}"
        return f"{kind}|{ratio!r}|{v!r}|{theta!r}|{len(c_nodes)}{other}"

    def get(self, key: str) -> tuple[float, np.ndarray] | None:
        got = self.rows.get(key)
        return None if got is None else (got[0], np.asarray(got[1]))

    def put(self, key: str, s_c: float, q: Any) -> None:
        """Keep ``(s_c, q)`` under ``key``, in memory and as one line of the file."""
        row = (float(s_c), np.asarray(q, dtype=float).tolist())
        self.rows[key] = row
        append_row(self.path, {"key": key, "s_c": row[0], "q": row[1]})


NODE_SOURCES = ("models.py", "scene.py", "errors.py", "solver/meniscus")
"""What a solved branch depends on: the ``meniscus`` solver and what it imports."""
