"""The two-angle sphere-pair table's cost: where it goes, and what sub-pieces would save.

``calibrated-capillary`` evaluates two spheres with two contact angles at 1.3-1.5 us a
point in double precision (``bench_calibrate``, 2026-11-25), and at about 0.75x that with
its force's train in single precision (the default since 2026-11-26), against the 1 us
goal of issue 11. This benchmark measures,
in one run on the points of ``bench_pair_tt`` (1e5, one BLAS thread, alternating rounds,
median of 7):

- **shipped (default)**: the package's evaluation of the two-angle pair table, as
  ``calibrated_capillary.force_star`` does it at its default precision (the force's tensor
  train summed in float32, everything else in float64), through :func:`evaluate` like
  every form here (checked to reproduce ``force_star`` bit for bit; ``force_star``'s own
  split of a batch into one- and two-angle points is not timed);
- **double (accurate preset)**: the same with every train summed in float64
  (``precision="double"``, what the exports compute; what shipped until 2026-11-26);
- **structure only**: the double form's pieces, axes and calls with every tensor-train
  core cut to rank 1: what everything but the ranks costs (Chebyshev rows, ridge and onset series,
  gap coordinate, the per-batch calls and their elementwise sums);
- **no train sums**: the trains not evaluated at all (the rest of the pipeline);
- **b1 sub-pieces (K)**: each piece split along the small sphere's angle coordinate b1
  into K equal sub-ranges. A piece's fit is a polynomial in b1, so its rupture table and
  force factors are re-expanded on each sub-range exactly (Chebyshev interpolation at as
  many nodes as terms, :func:`restrict`), trailing b1 terms whose largest coefficient is
  below :data:`TRIM` dropped, and the trains rebuilt at the shipped truncation
  (``calibrated_capillary.train_piece``). Evaluated by the package's own piece code on the
  points of each sub-range (:func:`evaluate`); not a format the package or its exports
  read.
- **every train in float32**: the rupture trains' cores too in single precision, and the
  Chebyshev rows cast to it as each train is summed (not shipped: S_c would move, by up
  to 3.3e-7, and with it the rupture window; the shipped default keeps S_c in float64).

For each form: the cost a point, the multiply-adds a point of its trains weighted by the
points each piece evaluates, and the largest change against the double form's values
(rupture distance; force short of 0.999 S_c, where the held-out points stop, and
everywhere the force is nonzero). For K = 4 it also gives the multiply-adds if the force's
gap axis were halved too (the package cannot evaluate a gap sub-range: multiply-adds
only).

Writes ``benchmarks/results/pair_split.json`` and ``pair_split.png``. Run:
``python benchmarks/bench_pair_split.py`` (about 10 minutes: the sub-pieces' trains try
every axis order).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (  # noqa: E402
    alternating_medians,
    cost_bars,
    main_or_chart,
    save_chart,
    write_json,
)
from bench_pair_tt import N, points, shipped_pair_table  # noqa: E402

from wetcontact.generate import calibrated_capillary as gen  # noqa: E402
from wetcontact.reduced_models import calibrated_capillary as cc  # noqa: E402

TRIM = 1e-7
"""Trailing b1 coefficients of a sub-piece's tables dropped while their largest magnitude
is below this (the force exponent and log S_c are O(1))."""
SPLITS = (2, 4)
B1_AXIS, GAP_AXIS = 2, 4


def restrict(coef: np.ndarray, axis: int, lo: float, hi: float) -> np.ndarray:
    """The Chebyshev coefficients along ``axis`` of the same polynomial on the sub-range
    [lo, hi] of [-1, 1], mapped to [-1, 1]: interpolation at n Chebyshev points of the
    first kind, exact for the degree n - 1 the table has (to round-off)."""
    n = coef.shape[axis]
    x = np.cos(np.pi * (np.arange(n) + 0.5) / n)
    old = cc._cheb_rows(lo + 0.5 * (hi - lo) * (x + 1.0), n)  # T_j at the nodes, (j, i)
    new = cc._cheb_rows(x, n)
    weights = np.full(n, 2.0 / n)
    weights[0] = 1.0 / n
    m = old @ (new.T * weights)  # T_j(x(x')) = sum_k m[j, k] T_k(x')
    return np.moveaxis(np.tensordot(np.moveaxis(coef, axis, -1), m, 1), -1, axis)


def kept_terms(coef: np.ndarray, axis: int) -> int:
    """Terms along ``axis`` up to the last whose largest coefficient reaches :data:`TRIM`."""
    peak = np.abs(np.moveaxis(coef, axis, 0)).reshape(coef.shape[axis], -1).max(axis=1)
    big = np.flatnonzero(peak >= TRIM)
    return int(big[-1]) + 1 if big.size else 1


def sub_piece(piece: dict[str, Any], lo: float, hi: float) -> dict[str, Any]:
    """``piece`` on b1 in [lo, hi]: its fit re-expanded there (:func:`restrict`), trimmed
    and trained at the shipped truncation."""
    rup = restrict(np.asarray(piece["rupture"]), B1_AXIS, lo, hi)
    left = restrict(np.asarray(piece["force_left"]), B1_AXIS, lo, hi)
    n = max(kept_terms(rup, B1_AXIS), kept_terms(left, B1_AXIS))
    fit = {k: v for k, v in piece.items() if k not in cc.TRAIN_FIELDS}
    return gen.train_piece({**fit, "rupture": rup[:, :, :n].tolist(),
                           "force_left": left[:, :, :n].tolist(),
                           "force_right": np.asarray(piece["force_right"]).tolist()})


def split_table(entry: dict[str, Any], k: int) -> list[list[tuple[float, float, Any]]]:
    """Per band, its K b1 sub-ranges with their pieces (arrays, as the package reads)."""
    edges = np.linspace(-1.0, 1.0, k + 1)
    out = []
    for band in entry["bands"]:
        subs = []
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            sub = {"pieces": [sub_piece(p, float(lo), float(hi)) for p in band["pieces"]]}
            subs.append((float(lo), float(hi), cc.as_arrays({"s": sub})["s"]))
        out.append(subs)
    return out


def evaluate(entry: dict[str, Any], subs: list[Any] | None, pts: tuple[np.ndarray, ...],
             dtype: Any = np.float64) -> tuple[np.ndarray, np.ndarray]:
    """``force_star``'s two-angle pair path (``F/(2 pi sigma R_s)``, S_c/R_s), each band's
    points in their b1 sub-range's pieces (``subs``; ``None``: the band's own pieces), the
    force's trains summed in ``dtype`` (float32: the package's default precision)."""
    v, th, s, ratio, tw = pts
    rho = cc.reduced_star("sphere-sphere", ratio)
    ts = np.degrees(th)
    lead = [cc.ratio_coordinate(ratio), cc.volume_coordinate(v)]
    f, s_c = np.full(v.size, np.nan), np.full(v.size, np.nan)
    for band, m, b1 in cc._by_band(entry, ts, lead):
        lm = cc._take(lead, m)
        split = cc.theta_split_deg(band, lm, b1)
        if subs is None:  # the band's own pieces, b1 as it is
            f[m], s_c[m] = cc._pieces(band, [*lm, b1], np.degrees(tw[m]), split, v[m], s[m],
                                      rho[m], None, ts[m], dtype)
            continue
        at = next(i for i, b in enumerate(entry["bands"]) if b is band)
        for j, (lo, hi, table) in enumerate(subs[at]):
            mm = np.flatnonzero((b1 <= hi) & ((b1 > lo) if j else True))
            if mm.size:
                g = m[mm]
                f[g], s_c[g] = cc._pieces(
                    table, [*cc._take(lm, mm), cc._map(b1[mm], lo, hi)],
                    np.degrees(tw[g]), split[mm], v[g], s[g], rho[g], None, ts[g], dtype)
    return f * (np.cos(th) + np.cos(tw)), s_c


def with_cores(entry: dict[str, Any], fields: tuple[str, ...], change: Any
               ) -> dict[str, Any]:
    """The table with ``change`` applied to every core of the named trains of each piece."""
    def piece(p: dict[str, Any]) -> dict[str, Any]:
        return {**p, **{k: {**p[k], "cores": [change(np.asarray(g)) for g in p[k]["cores"]]}
                        for k in fields if k in p}}
    return {**entry, "bands": [{**b, "pieces": [piece(p) for p in b["pieces"]]}
                               for b in entry["bands"]]}


def rank_one(entry: dict[str, Any]) -> dict[str, Any]:
    """The table with every train core cut to rank 1 (its first slice)."""
    return with_cores(entry, cc.TRAIN_FIELDS, lambda g: g[:1, :, :1])


def single(entry: dict[str, Any], fields: tuple[str, ...]) -> dict[str, Any]:
    """The table with the named trains' cores in float32."""
    return with_cores(entry, fields, lambda g: g.astype(np.float32))


def in_core_precision(entry: dict[str, Any], pts: tuple[np.ndarray, ...]
                      ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`evaluate`, each train summed in its cores' precision: the package's
    ``train_sum`` on the Chebyshev rows cast to the cores' dtype (without the cast numpy
    would promote every product back to float64)."""
    inner = cc.train_sum

    def cast(train: dict[str, Any], rows: list[np.ndarray]) -> np.ndarray:
        dtype = train["cores"][0].dtype
        return inner(train, [r.astype(dtype, copy=False) for r in rows])

    cc.kernel.train_sum = cast
    try:
        return evaluate(entry, None, pts)
    finally:
        cc.kernel.train_sum = inner


def train_macs(piece: dict[str, Any]) -> int:
    """Multiply-adds a point of a piece's trains."""
    return int(sum(np.asarray(g).size for k in cc.TRAIN_FIELDS if k in piece
                   for g in piece[k]["cores"]))


def piece_points(entry: dict[str, Any], subs: Any, pts: tuple[np.ndarray, ...]
                 ) -> list[tuple[dict[str, Any], int]]:
    """Each piece :func:`evaluate` would use, with the number of points it takes."""
    seen: list[tuple[dict[str, Any], int]] = []
    inner = cc._piece

    def counting(piece: dict[str, Any], lo: Any, hi: Any, idx: np.ndarray, *a: Any) -> Any:
        seen.append((piece, idx.size))
        return np.zeros(idx.size), np.ones(idx.size)

    cc.kernel._piece = counting
    try:
        evaluate(entry, subs, pts)
    finally:
        cc.kernel._piece = inner
    return seen


def gap_halved_macs(piece: dict[str, Any]) -> float:
    """A piece's multiply-adds a point if its force table were also halved along the gap
    axis (each half re-expanded, trimmed and trained as :func:`sub_piece`; their mean)."""
    coef = gen.train_fits(piece, ("force_train",))["force_train"]
    tol = gen.TRAIN_TOL["force_train"]
    got = []
    for lo, hi in ((-1.0, 0.0), (0.0, 1.0)):
        c = restrict(coef, GAP_AXIS, lo, hi)
        c = c[..., :kept_terms(c, GAP_AXIS)]
        got.append(sum(np.asarray(g).size for g in gen.train_of(c, tol)["cores"]))
    return float(np.mean(got)) + sum(np.asarray(g).size
                                     for g in piece["rupture_train"]["cores"])


def main() -> None:
    entry = shipped_pair_table("bench_pair_split")
    pts = points()
    v, th, gap, ratio, tw = pts
    subs = {k: split_table(entry, k) for k in SPLITS}
    print("sub-pieces trained", flush=True)
    # every form is timed through evaluate: check it against both precisions
    for dtype, precision in ((np.float32, "mixed"), (np.float64, "double")):
        want = cc.force_star("sphere-sphere", v, th, gap, ratio, theta_wall=tw,
                             precision=precision)
        mine = evaluate(entry, None, pts, dtype)
        if not (np.array_equal(mine[0], want[0]) and np.array_equal(mine[1], want[1])):
            sys.exit("bench_pair_split: evaluate no longer reproduces force_star's two-angle "
                     f"pair path bit for bit (precision {precision})")
    f0, sc0 = want  # the double form's: what every change is measured against
    flat = rank_one(entry)
    low = {"every train in float32": single(entry, cc.TRAIN_FIELDS)}
    fns = {"double (accurate preset)": lambda: evaluate(entry, None, pts),
           "shipped (default: force train in float32)":
               lambda: evaluate(entry, None, pts, np.float32),
           "structure only (rank-1 cores)": lambda: evaluate(flat, None, pts)}
    fns.update({f"b1 sub-pieces (K = {k})": (lambda k=k: evaluate(entry, subs[k], pts))
                for k in SPLITS})
    fns.update({name: (lambda t=t: in_core_precision(t, pts)) for name, t in low.items()})
    inner = cc.train_sum
    cost = alternating_medians(fns)
    cc.kernel.train_sum = lambda train, rows: np.zeros(rows[0].shape[1])
    try:
        cost["no train sums"] = alternating_medians(
            {"x": lambda: evaluate(entry, None, pts)})["x"]
    finally:
        cc.kernel.train_sum = inner
    forms: dict[str, Any] = {}
    for name, t in cost.items():
        forms[name] = {"s_per_point": t / N}

    def weighted(subs_k: Any, macs: Any = train_macs) -> float:
        return sum(macs(p) * n for p, n in piece_points(entry, subs_k, pts)) / N

    def changes(rec: dict[str, Any], f: np.ndarray, sc: np.ndarray) -> None:
        short = (gap < 0.999 * np.minimum(sc, sc0)) & (f0 > 0)
        both = (f > 0) & (f0 > 0)
        rec["max_change_rupture_vs_double"] = float(np.max(np.abs(sc / sc0 - 1.0)))
        rec["max_change_force_vs_double_short_of_0.999_sc"] = float(
            np.max(np.abs(f[short] / f0[short] - 1.0)))
        rec["max_change_force_vs_double"] = float(np.max(np.abs(f[both] / f0[both] - 1.0)))

    forms["double (accurate preset)"]["macs_per_point"] = weighted(None)
    shipped = forms["shipped (default: force train in float32)"]
    shipped["macs_per_point"] = weighted(None)
    changes(shipped, *evaluate(entry, None, pts, np.float32))
    for k in SPLITS:
        rec = forms[f"b1 sub-pieces (K = {k})"]
        rec["macs_per_point"] = weighted(subs[k])
        changes(rec, *evaluate(entry, subs[k], pts))
        rec["b1_terms"] = sorted({int(np.asarray(p["rupture"]).shape[B1_AXIS])
                                  for band in subs[k] for _, _, t in band
                                  for p in t["pieces"]})
    for name, t in low.items():
        forms[name]["macs_per_point"] = shipped["macs_per_point"]
        changes(forms[name], *in_core_precision(t, pts))
    forms["b1 sub-pieces (K = 4)"]["macs_per_point_gap_halved_too"] = weighted(
        subs[4], gap_halved_macs)
    result = {"points": N, "blas_threads": os.environ["OPENBLAS_NUM_THREADS"], "trim": TRIM,
              "forms": forms}
    write_json("pair_split", result)
    chart(result)
    for name, rec in forms.items():
        print(f"{name}: {rec['s_per_point'] * 1e6:.2f} us a point, "
              + ", ".join(f"{k} {v:.3g}" for k, v in rec.items()
                          if k != "s_per_point" and not isinstance(v, list)), flush=True)


def chart(result: dict[str, Any]) -> None:
    forms = result["forms"]
    fig, ax, names, cost = cost_bars(forms, (9.5, 3.8))
    for y, (c, n) in enumerate(zip(cost, names, strict=True)):
        macs = forms[n].get("macs_per_point")
        halved = forms[n].get("macs_per_point_gap_halved_too")
        ax.text(c, y, f" {c:.2f} us" + ("" if macs is None else f", {macs:.0f} MACs")
                + ("" if halved is None else f"\n ({halved:.0f} MACs with the gap halved too)"),
                va="center", fontsize=9,
                bbox={"facecolor": "white", "edgecolor": "none", "pad": 0.5})
    ax.axvline(1.0, color="k", ls="--", lw=1, zorder=0)
    ax.text(1.0, len(names) - 0.5, " 1 us goal", fontsize=9)
    ax.invert_yaxis()
    ax.set_xlim(0, max(cost) * 1.45)
    ax.set_xlabel("cost a point (us, one BLAS thread, 1e5 points)")
    ax.set_title("calibrated-capillary, two spheres with two contact angles: "
                 "where the cost goes")
    save_chart(fig, "pair_split")


if __name__ == "__main__":
    main_or_chart("pair_split", main, chart)
