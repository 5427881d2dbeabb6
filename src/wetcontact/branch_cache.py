"""Solved ``meniscus`` branches kept in the user cache, so that work that is killed or fails
loses nothing already computed: the calibrated-capillary generator's tensor nodes and
held-out bridges, and the rupture distances a study's gaps are scaled by."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np


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
        from wetcontact.store import source_hash

        base = folder or Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
        self.path = (base if folder else base / "wetcontact") / (
            f"{prefix}-" + source_hash(NODE_SOURCES) + ".jsonl")
        self.rows: dict[str, tuple[float, list[float]]] = {}
        if self.path.is_file():
            for line in self.path.read_text().splitlines():
                try:
                    row = json.loads(line)
                    self.rows[row["key"]] = (row["s_c"], row["q"])
                except (ValueError, KeyError):
                    continue  # a line cut by a kill

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
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with self.path.open("a") as fh:
                fh.write(json.dumps({"key": key, "s_c": row[0], "q": row[1]}) + "\n")
        except OSError:
            pass  # a read-only cache costs a rerun, not the generation


NODE_SOURCES = ("models.py", "scene.py", "errors.py", "solver/meniscus")
"""What a solved branch depends on: the ``meniscus`` solver and what it imports."""
