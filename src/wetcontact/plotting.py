"""Shared figure conventions of the report: distinct styles, signed axes, saving.

Every line in one plot gets its own colour (:data:`COLOURS`, 20 clearly different ones)
and its own marker, so no two series can be confused even in grey print; forces are drawn
signed on a symmetric-log axis (attraction below zero, repulsion above). matplotlib is
imported only here and only when a figure is drawn.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

# tab10 plus ten more hues distinct from it (enough for every registered model in one plot)
COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf", "#000000", "#b8860b", "#000080", "#00ff7f",
           "#800000", "#008080", "#ff00ff", "#4b0082", "#9acd32", "#ffd700")
MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*", "<", ">", "h", "p", "d", "8", "H",
           "1", "2", "3", "4", "+")
LINESTYLES = ("-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)))


def styles(names: Sequence[str]) -> dict[str, dict[str, Any]]:
    """A distinct colour and marker, and a line style, per name (in the order given; the
    keyword arguments of ``Axes.plot``); ValueError past 20 names."""
    names = list(dict.fromkeys(names))
    if len(names) > len(COLOURS):
        raise ValueError(f"{len(names)} series in one plot; at most {len(COLOURS)} distinct "
                         "colours")
    return {n: {"color": COLOURS[i], "marker": MARKERS[i],
                "linestyle": LINESTYLES[i % len(LINESTYLES)]} for i, n in enumerate(names)}


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def symlog_threshold(values: Sequence[np.ndarray]) -> float:
    """Linear range of a symlog axis: the smallest non-zero |value| (1 if all are zero)."""
    nz = [np.min(np.abs(v[v != 0])) for v in values if np.any(v != 0)]
    return float(min(nz)) if nz else 1.0


def save(fig: Any, path: str | Path, dpi: int = 110) -> None:
    """Save ``fig`` to ``path`` and close it."""
    plt = pyplot()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def clipped_texts(fig: Any) -> list[str]:
    """The axes (by title or label) whose drawn labels, titles or tick labels stick out of
    the figure canvas; used by the tests to check that no figure clips a label."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    out = []
    for ax in fig.axes:
        bb = ax.get_tightbbox(renderer)
        if bb is None:
            continue
        if bb.x0 < box.x0 - 1 or bb.y0 < box.y0 - 1 or bb.x1 > box.x1 + 1 or bb.y1 > box.y1 + 1:
            out.append(ax.get_title() or ax.get_ylabel() or ax.get_xlabel() or "axes")
    return out


def overlapping_ticks(ax: Any) -> int:
    """Number of adjacent x tick labels (major and minor) of ``ax`` whose boxes overlap."""
    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = sorted((t.get_window_extent(renderer) for t in ax.get_xticklabels(which="both")
                    if t.get_visible() and t.get_text()
                    and _inside(ax, t.get_position()[0])), key=lambda b: b.x0)
    return sum(a.x1 > b.x0 + 0.5 for a, b in zip(boxes, boxes[1:], strict=False))


def _inside(ax: Any, x: float) -> bool:
    lo, hi = sorted(ax.get_xlim())
    return lo <= x <= hi
