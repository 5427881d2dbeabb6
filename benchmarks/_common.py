"""Shared helpers for the accuracy-versus-time benchmarks (JSON + PNG into benchmarks/results)."""

from __future__ import annotations

import json
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

RESULTS = Path(__file__).resolve().parent / "results"


def median_time(fn: Callable[[], Any], repeats: int = 5, warmup: int = 1) -> tuple[float, Any]:
    """Median wall time (s) of ``repeats`` calls after ``warmup`` calls; also the last result."""
    out = None
    for _ in range(warmup):
        out = fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main_or_chart(name: str, main: Callable[[], Any],
                  chart: Callable[[dict[str, Any]], Any]) -> None:
    """Run a benchmark's ``main``, or with ``--chart`` on the command line redraw its chart
    from ``benchmarks/results/<name>.json`` (written by an earlier run)."""
    if "--chart" in sys.argv:
        chart(json.loads((RESULTS / f"{name}.json").read_text()))
    else:
        main()


def write_json(name: str, data: dict[str, Any]) -> Path:
    """Write ``benchmarks/results/<name>.json`` with the machine's core count attached."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    data = {"cpu_count": os.cpu_count(), **data}
    path = RESULTS / f"{name}.json"
    path.write_text(json.dumps(data, indent=2, default=float))
    return path
