"""Shared figure conventions of the report: distinct styles, signed axes, saving.

Every line in one plot gets its own colour (:data:`COLOURS`, 20 clearly different ones),
marker and dash pattern, so no two series can be confused even in grey print; forces are
drawn signed (:func:`signed_axis`: attraction below the zero line, repulsion above, on a
symmetric-log axis when they span two decades or more). matplotlib is
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
# twenty dash patterns, one per colour: curves that coincide still show both dashes
LINESTYLES = ("-", (0, (6, 2)), (0, (6, 2, 1, 2)), (0, (1, 1.5)), (0, (5, 1, 1, 1, 1, 1)),
              (0, (10, 3)), (0, (3, 1)), (0, (3, 1, 1, 1)), (0, (8, 2, 2, 2, 2, 2)),
              (0, (2, 3)), (0, (12, 2, 2, 2)), (0, (4, 1, 4, 1, 1, 1)), (0, (7, 1, 1, 1)),
              (0, (1, 3)), (0, (5, 2, 5, 2, 1, 2)), (0, (3, 3)), (0, (9, 1, 2, 1)),
              (0, (4, 2, 1, 2, 1, 2, 1, 2)), (0, (2, 1, 2, 1, 6, 1)), (0, (15, 2, 1, 2)))


def styles(names: Sequence[str]) -> dict[str, dict[str, Any]]:
    """A distinct colour, marker and line style per name (in the order given; the
    keyword arguments of ``Axes.plot``); ValueError past 20 names."""
    names = list(dict.fromkeys(names))
    if len(names) > len(COLOURS):
        raise ValueError(f"{len(names)} series in one plot; at most {len(COLOURS)} distinct "
                         "colours")
    return {n: {"color": COLOURS[i], "marker": MARKERS[i], "linestyle": LINESTYLES[i]}
            for i, n in enumerate(names)}


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def symlog_threshold(values: Sequence[np.ndarray], decades: float = 8.0) -> float:
    """Linear range of a symlog axis: the power of ten at or below the smallest non-zero
    |value|, but no more than ``decades`` below the largest (so that values passing close
    to zero do not stretch the axis); 1 if all are zero."""
    nz = [np.abs(v[np.isfinite(v) & (v != 0)]) for v in values]
    nz = [a for a in nz if a.size]
    if not nz:
        return 1.0
    lo, hi = min(float(a.min()) for a in nz), max(float(a.max()) for a in nz)
    return float(10.0 ** np.floor(np.log10(max(lo, hi * 10.0 ** -decades))))


def signed_axis(ax: Any, values: Sequence[np.ndarray], decades: float = 2.0) -> float | None:
    """Make ``ax``'s y axis show the signed ``values`` with the zero line in view.

    Symmetric-logarithmic (:func:`symlog_threshold`, one decade of linear band per side,
    shaded) when the non-zero magnitudes span at least ``decades`` decades, linear
    otherwise; the limits are the values' range, widened to include zero, plus 4 % in the
    axis' own coordinates. Returns the linear band's half-width, or None on a linear axis.
    """
    finite = [v[np.isfinite(v)] for v in values]
    nz = np.concatenate([np.abs(v[v != 0]) for v in finite] or [np.zeros(0)])
    lin = None
    if nz.size and nz.max() >= 10.0 ** decades * nz.min():
        lin = symlog_threshold(finite)
        ax.set_yscale("symlog", linthresh=lin, linscale=1.0)
    allv = np.concatenate([*finite, np.zeros(1)])
    half = 0.5 * lin if lin is not None else 0.0
    tr = ax.yaxis.get_transform()
    lo, hi = tr.transform([min(allv.min(), -half), max(allv.max(), half)])
    if hi == lo:
        lo, hi = lo - 1.0, hi + 1.0
    pad = 0.04 * (hi - lo)
    ax.set_ylim(*tr.inverted().transform([lo - pad, hi + pad]))
    ax.axhline(0.0, color="0.25", lw=0.8, zorder=0)
    if lin is not None:
        ax.axhspan(-lin, lin, color="0.92", zorder=-1)
    else:  # "-3.5e-4", not "-0.00035" with five zeros on the axis
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    return lin


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
