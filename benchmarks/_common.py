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


def alternating_medians(fns: dict[str, Callable[[], Any]], rounds: int = 7
                        ) -> dict[str, float]:
    """Median wall time (s) of each callable over ``rounds`` alternating rounds, after one
    warm-up call each: forms compared in one run see the same drifts of a shared machine's
    speed (which varies by up to 1.5x within minutes)."""
    got: dict[str, list[float]] = {k: [] for k in fns}
    for fn in fns.values():
        fn()
    for _ in range(rounds):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            got[k].append(time.perf_counter() - t0)
    return {k: statistics.median(v) for k, v in got.items()}


def main_or_chart(name: str, main: Callable[[], Any],
                  chart: Callable[[dict[str, Any]], Any]) -> None:
    """Run a benchmark's ``main``, or with ``--chart`` on the command line redraw its chart
    from ``benchmarks/results/<name>.json`` (written by an earlier run)."""
    if "--chart" in sys.argv:
        chart(json.loads((RESULTS / f"{name}.json").read_text()))
    else:
        main()


def machine() -> dict[str, Any]:
    """What a timing depends on: CPU model, cores, load, date, commit and library versions."""
    import datetime
    import platform
    import subprocess

    import numpy
    import scipy

    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next((ln.split(":", 1)[1].strip() for ln in fh
                        if ln.startswith("model name")), cpu)
    except OSError:
        pass
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, cwd=RESULTS.parent, check=False).stdout.strip()
    except OSError:
        commit = ""
    return {"cpu": cpu, "cores": os.cpu_count(),
            "load_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
            "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "commit": commit or None, "python": platform.python_version(),
            "numpy": numpy.__version__, "scipy": scipy.__version__}


def write_json(name: str, data: dict[str, Any]) -> Path:
    """Write ``benchmarks/results/<name>.json`` with the machine it ran on attached
    (:func:`machine`, taken as it is written: the end of the run; a partial rerun that
    keeps older parts of the file records its own machine)."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    data = {"cpu_count": os.cpu_count(), **data, "machine": machine()}
    path = RESULTS / f"{name}.json"
    path.write_text(json.dumps(data, indent=2, default=float))
    return path


HATCHES = ("", "//", "..", "\\\\", "xx", "--", "++")
"""Bar hatches, one a form, so that the bars differ without their colours."""


def cost_bars(forms: dict[str, dict[str, Any]], figsize: tuple[float, float]) -> tuple[Any, ...]:
    """A horizontal bar chart of each form's ``s_per_point`` in us (colour and hatch a
    form, Agg backend): ``(fig, ax, names, cost)``; :func:`save_chart` writes it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(forms)
    cost = [forms[n]["s_per_point"] * 1e6 for n in names]
    fig, ax = plt.subplots(figsize=figsize)
    ax.barh(names, cost, color=[f"C{i}" for i in range(len(names))],
            hatch=[HATCHES[i % len(HATCHES)] for i in range(len(names))], edgecolor="k")
    return fig, ax, names, cost


def save_chart(fig: Any, name: str) -> Path:
    """Lay out ``fig`` and write it as ``RESULTS/name.png`` (120 dpi), then close it."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    path = RESULTS / f"{name}.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path

