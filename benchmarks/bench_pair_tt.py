"""Would a tensor train cut the two-angle sphere-pair table's cost? Measured, not shipped.

The shipped ``calibrated-capillary`` table for sphere pairs with two contact angles costs
about 4 us a point (``bench_calibrate.py``) against the 1 us goal: per point, its pieces
contract a dense rupture table ``S(w, a, b1, b2)`` (729 x 15 or 729 x 27 multiply-adds) and
a rank-r force table ``sum_k L_k(w, a, b1) R_k(b2, c)`` (r (729 + 285) or r (729 + 513),
r = 24-40), both in Chebyshev coefficients. This benchmark writes each piece's coefficient
tensor as a tensor train (TT-SVD, Oseledets 2011, SIAM J. Sci. Comput. 33, 2295: a chain
of SVDs of the tensor's unfoldings, each truncated where the discarded singular values'
2-norm reaches ``tol``),

    C_{i1..id} ~ G1[i1] G2[i2] ... Gd[id],   Gk[ik] an r_{k-1} x r_k matrix,

over the axis order with the fewest multiply-adds, and evaluates it per point as a chain of
matrix products over the batch (``V <- (V Gk) . T(x_k)``: one BLAS product, then the
sum over the axis's Chebyshev rows). It reports per piece, for the shipped form and each
truncation: the ranks, multiply-adds a point, seconds a point (1e5 points uniform in the
coefficient box, one BLAS thread, median of 5) and the largest change of the table's
exponent (log q for the force, log(S_c / V^(1/3)) for the rupture distance; the relative
change of the force or rupture distance is about the same number) on those points and, as
a bound valid at every point, the sum of the absolute coefficient changes (|T_k| <= 1).

End to end, per truncation: ``force_star`` on ``bench_calibrate``'s 1e5 two-angle pair
points with the trains in place of the shipped contractions (``ccap._piece`` swapped for
:func:`piece_with_trains` for the measurement only), against the shipped form in the same
run, and the table's held-out tables (``calibrate_pairs2.pair_held_out``: 500 bridges,
4000 force points, against fresh ``meniscus``, cached in the node cache after the first
run; about 1 minute from an empty cache) with either form. Nothing in the package is
changed: shipping a train needs new table fields and its C and Python exports.

Writes ``benchmarks/results/pair_tt.json`` and ``pair_tt.png``. Run:
``python benchmarks/bench_pair_tt.py`` (about 3 minutes from an empty node cache).
"""

from __future__ import annotations

import itertools
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

# one BLAS thread before numpy loads, as bench_calibrate's per-point costs
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, median_time, write_json  # noqa: E402

from wetcontact.reduced_models import calibrated_capillary as ccap  # noqa: E402

N = 100_000
FORCE_TOLS = (3e-6, 1e-5, 3e-5)
RUPTURE_TOLS = (1e-7, 1e-6, 1e-5)
TT_CHUNK = 512


def tt_svd(coef: np.ndarray, tol: float) -> list[np.ndarray]:
    """Tensor-train cores ``G_k`` (r_{k-1}, n_k, r_k) of ``coef`` by sequential truncated
    SVDs (Oseledets 2011, algorithm 1), each dropping the trailing singular values whose
    2-norm is at most ``tol``."""
    cores, rank, rest = [], 1, np.asarray(coef, dtype=float)
    for n_k in coef.shape[:-1]:
        u, s, vt = np.linalg.svd(rest.reshape(rank * n_k, -1), full_matrices=False)
        tail = np.sqrt(np.cumsum(s[::-1] ** 2))[::-1]  # 2-norm of s[j:]
        keep = max(1, int(np.sum(tail > tol)))
        cores.append(u[:, :keep].reshape(rank, n_k, keep))
        rest, rank = s[:keep, None] * vt[:keep], keep
    cores.append(rest.reshape(rank, coef.shape[-1], 1))
    return cores


def tt_full(cores: list[np.ndarray]) -> np.ndarray:
    """The tensor a train represents (for the coefficient-change bound)."""
    out = cores[0][0]
    for g in cores[1:]:
        out = np.tensordot(out, g, axes=1)
    return out[..., 0]


def tt_eval(cores: list[np.ndarray], rows: list[np.ndarray]) -> np.ndarray:
    """``sum C_{i..} T_i(x_1) ...`` per point from the train's cores and the points'
    coefficient-major Chebyshev rows (``ccap._cheb_rows``), ``TT_CHUNK`` points at a time:
    per core one matrix product over the batch and one sum over the core's axis."""
    n = rows[0].shape[1]
    out = np.empty(n)
    mats = [g.reshape(g.shape[0], -1) for g in cores[1:]]
    for lo in range(0, n, TT_CHUNK):
        sl = slice(lo, min(n, lo + TT_CHUNK))
        v = rows[0][:, sl].T @ cores[0][0]
        for g, m, t in zip(cores[1:], mats, rows[1:], strict=True):
            w = (v @ m).reshape(v.shape[0], g.shape[1], g.shape[2])
            v = np.einsum("nmr,mn->nr", w, t[:, sl])
        out[sl] = v[:, 0]
    return out


def macs(cores: list[np.ndarray]) -> int:
    """Multiply-adds a point of :func:`tt_eval`."""
    return int(sum(g.size for g in cores))


def best_order(coef: np.ndarray, tol: float) -> tuple[int, ...]:
    """The axis order whose train at ``tol`` has the fewest multiply-adds (all orders)."""
    return min(itertools.permutations(range(coef.ndim)),
               key=lambda p: macs(tt_svd(coef.transpose(p), tol)))


def shipped(piece: dict, rows: list[np.ndarray]) -> tuple[dict, np.ndarray, np.ndarray]:
    """The shipped contractions as ``ccap._piece`` does them (its chunk size): seconds a
    point of the rupture sum, of the force sum (each with the outer products it needs) and
    of both together (sharing the lead axes' outer product, as ``_piece``), and the two
    sums' values."""
    rup = np.asarray(piece["rupture"])
    left, right = np.asarray(piece["force_left"]), np.asarray(piece["force_right"])
    dims = (*left.shape[:-1], *right.shape[1:])
    k = left.ndim - 1
    chunk = ccap.piece_chunk(dims, k)
    rup2 = rup.reshape(-1, rup.shape[-1]).T
    n = rows[0].shape[1]

    def rupture() -> np.ndarray:
        out = np.empty(n)
        for lo in range(0, n, chunk):
            sl = slice(lo, lo + chunk)
            lead = ccap._outer([r[:, sl] for r in rows[:k]])
            out[sl] = np.einsum("ij,ij->j", rup2 @ lead, rows[k][:, sl])
        return out

    def force() -> np.ndarray:
        out = np.empty(n)
        for lo in range(0, n, chunk):
            sl = slice(lo, lo + chunk)
            out[sl] = ccap.low_rank_rows(left, right, ccap._outer([r[:, sl] for r in rows[:k]]),
                                         ccap._outer([r[:, sl] for r in rows[k:]]))
        return out

    def both() -> None:  # as _piece: the lead axes' outer product serves both sums
        for lo in range(0, n, chunk):
            sl = slice(lo, lo + chunk)
            lead = ccap._outer([r[:, sl] for r in rows[:k]])
            np.einsum("ij,ij->j", rup2 @ lead, rows[k][:, sl])
            ccap.low_rank_rows(left, right, lead, ccap._outer([r[:, sl] for r in rows[k:]]))

    t_r, z = median_time(rupture, repeats=5)
    t_f, y = median_time(force, repeats=5)
    t_b, _ = median_time(both, repeats=5)
    return ({"rupture_s_per_point": t_r / n, "force_s_per_point": t_f / n,
             "both_s_per_point": t_b / n,
             "force_rank": int(left.shape[-1]),
             "rupture_macs": int(rup.size), "force_macs": int(left.shape[-1] * (
                 np.prod(dims[:k]) + np.prod(dims[k:])))}, z, y)


def trains(coef: np.ndarray, rows: list[np.ndarray], exact: np.ndarray,
           tols: tuple[float, ...]) -> list[dict]:
    """Each truncation's train over the best axis order at the middle tolerance."""
    order = best_order(coef, tols[1])
    out = []
    for tol in tols:
        cores = tt_svd(coef.transpose(order), tol)
        ordered = [rows[i] for i in order]
        t, val = median_time(lambda c=cores, o=ordered: tt_eval(c, o), repeats=5)
        bound = np.abs(tt_full(cores).transpose(np.argsort(order)) - coef).sum()
        out.append({"tol": tol, "order": list(order), "ranks": [g.shape[2] for g in cores[:-1]],
                    "macs": macs(cores), "s_per_point": t / rows[0].shape[1],
                    "max_change_sampled": float(np.abs(val - exact).max()),
                    "max_change_bound": float(bound), "_cores": cores})
    return out


def piece_with_trains(trains: dict[int, tuple]) -> Callable[..., tuple]:
    """A stand-in for ``ccap._piece`` (same arguments and results) that evaluates each
    piece's rupture and force sums by its trains ``trains[id(piece)] = (rupture order,
    rupture cores, force order, force cores)``; everything else as ``_piece``."""
    def piece_fn(piece, lo, hi, idx, lead, piece_deg, v, s, rho, eps, chunk):  # noqa: ANN001, ANN202, ARG001
        order_r, cores_r, order_f, cores_f = trains[id(piece)]
        dims = (*np.shape(piece["force_left"])[:-1], *np.shape(piece["force_right"])[1:])
        rows = [ccap._cheb_rows(x[idx], m) for x, m in zip(lead, dims, strict=False)]
        rows.append(ccap._cheb_rows(ccap.piece_coordinate(piece, piece_deg[idx], lo[idx],
                                                          hi[idx]), dims[len(lead)]))
        sc = np.cbrt(v[idx]) * np.exp(tt_eval(cores_r, [rows[i] for i in order_r]))
        inside = s[idx] < sc
        rows.append(ccap._cheb_rows(ccap.gap_coordinate(np.where(inside, s[idx], 0.0), sc,
                                                        eps[idx]), dims[-1]))
        q = np.exp(tt_eval(cores_f, [rows[i] for i in order_f]))
        return np.where(inside, rho[idx] * q, 0.0), sc

    return piece_fn


def swapped(piece_fn: Callable[..., tuple] | None, fn: Callable[[], Any]) -> Any:
    """``fn()`` with ``ccap._piece`` replaced by ``piece_fn`` (None: the shipped one)."""
    inner = ccap._piece
    ccap._piece = piece_fn or inner
    try:
        return fn()
    finally:
        ccap._piece = inner


def held_out_maxima(entry: dict) -> dict[str, dict[str, float]]:
    """Max relative errors of rupture distance and force per held-out stratum."""
    from wetcontact.calibrate_pairs2 import pair_held_out

    return {k: {q: v[q]["max"] for q in ("rupture_distance", "force")}
            for k, v in pair_held_out(entry, 120, 2).items()}


def piece_shares() -> tuple[dict[int, int], Callable[[], Any]]:
    """Points per piece (keyed by the piece dict's id) of bench_calibrate's two-angle
    pair points, and a call of ``force_star`` on them."""
    rng = np.random.default_rng(1)  # bench_calibrate's draws, in its order
    v = np.exp(rng.uniform(np.log(1e-4), np.log(0.1), N))
    th = np.radians(rng.uniform(0, 70, N))
    ratio = np.exp(rng.uniform(0, np.log(10), N))
    tw = np.radians(rng.uniform(0, 70, N))
    _, sc = ccap.force_star("sphere-sphere", v, th, np.zeros(N), ratio, theta_wall=tw)
    gap = rng.uniform(0, 1.0, N) * sc
    counts: dict[int, int] = {}
    inner = ccap._piece

    def counting(piece, lo, hi, idx, *args):  # noqa: ANN001, ANN002, ANN202
        counts[id(piece)] = counts.get(id(piece), 0) + idx.size
        return inner(piece, lo, hi, idx, *args)

    def call() -> Any:
        return ccap.force_star("sphere-sphere", v, th, gap, ratio, theta_wall=tw)

    swapped(counting, call)
    return counts, call


def main() -> None:
    table = ccap.capillary_table()
    if table is None or ccap.PAIR_TWO_ANGLES not in table:
        sys.exit("bench_pair_tt: the package data has no two-angle sphere-pair table")
    entry = table[ccap.PAIR_TWO_ANGLES]
    counts, call = piece_shares()
    t_shipped, (f0, sc0) = median_time(call, repeats=5)
    rng = np.random.default_rng(7)
    pieces, objs = [], []
    for b, band in enumerate(entry["bands"]):
        for i, piece in enumerate(band["pieces"]):
            left, right = np.asarray(piece["force_left"]), np.asarray(piece["force_right"])
            dims = (*left.shape[:-1], *right.shape[1:])
            rows = [ccap._cheb_rows(rng.uniform(-1, 1, N), m) for m in dims]
            cost, z, y = shipped(piece, rows)
            rup = np.asarray(piece["rupture"])
            rec = {"band": b, "piece": i, "dims": list(dims), "shipped": cost,
                   "points_share": counts.get(id(piece), 0) / N,
                   "rupture_trains": trains(rup, rows[:rup.ndim], z, RUPTURE_TOLS),
                   "force_trains": trains(np.tensordot(left, right, axes=1), rows, y,
                                          FORCE_TOLS)}
            pieces.append(rec)
            objs.append(piece)
            print(f"band {b} piece {i}: shipped {cost['both_s_per_point'] * 1e6:.2f} us; "
                  f"trains (force 1e-5, rupture 1e-6) "
                  f"{rec['force_trains'][1]['s_per_point'] * 1e6:.2f} + "
                  f"{rec['rupture_trains'][1]['s_per_point'] * 1e6:.2f} us", flush=True)
    levels = {"shipped": {
        "s_per_point": t_shipped / N,
        # the table sums' share of it (pieces weighted by their points): the rest is not
        # in the tables (rows, maps, pieces, the gap coordinate, exp)
        "table_sums_s_per_point": sum(p["points_share"] * p["shipped"]["both_s_per_point"]
                                      for p in pieces),
        "held_out_max": held_out_maxima(entry)}}
    for j, (tf, tr) in enumerate(zip(FORCE_TOLS, RUPTURE_TOLS, strict=True)):
        fn = piece_with_trains({id(o): (p["rupture_trains"][j]["order"],
                                        p["rupture_trains"][j]["_cores"],
                                        p["force_trains"][j]["order"],
                                        p["force_trains"][j]["_cores"])
                                for o, p in zip(objs, pieces, strict=True)})
        t, (f, sc) = median_time(lambda fn=fn: swapped(fn, call), repeats=5)
        attached = (f > 0) & (f0 > 0)
        levels[f"trains: force tol {tf:.0e}, rupture tol {tr:.0e}"] = {
            "s_per_point": t / N,
            "max_change_force": float(np.max(np.abs(f[attached] / f0[attached] - 1.0))),
            "max_change_rupture": float(np.max(np.abs(sc / sc0 - 1.0))),
            "held_out_max": swapped(fn, lambda: held_out_maxima(entry))}
        levels[next(reversed(levels))]["held_out_max_change"] = max(
            abs(m - levels["shipped"]["held_out_max"][k][q]) for k, v in
            levels[next(reversed(levels))]["held_out_max"].items() for q, m in v.items())
        print(f"{tf:.0e}/{tr:.0e}: {t / N * 1e6:.2f} us a point (shipped "
              f"{t_shipped / N * 1e6:.2f})", flush=True)
    for p in pieces:
        for key in ("rupture_trains", "force_trains"):
            for tt in p[key]:
                tt.pop("_cores")
    out = {"points": N, "blas_threads": os.environ["OPENBLAS_NUM_THREADS"],
           "end_to_end": levels, "pieces": pieces}
    write_json("pair_tt", out)
    chart(out)
    print(json.dumps(levels, indent=1))


def chart(out: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
    markers = ["o", "s", "^", "D", "v", "P"]
    for ax, what, key in ((axes[0], "force", "force_trains"),
                          (axes[1], "rupture", "rupture_trains")):
        for n, p in enumerate(out["pieces"]):
            lab = f"band {p['band']}, {'upper' if p['piece'] else 'lower'} piece"
            tt, col = p[key], f"C{n}"
            x = [t["s_per_point"] * 1e6 for t in tt]
            ax.plot(x, [t["max_change_sampled"] for t in tt], ls="-", marker=markers[n],
                    color=col, label=lab)
            ax.plot(x, [t["max_change_bound"] for t in tt], ls="--", lw=0.8,
                    marker=markers[n], mfc="none", color=col)
            ax.axvline(p["shipped"][f"{what}_s_per_point"] * 1e6, ls=":", lw=1.2, color=col)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ticks = [0.1, 0.2, 0.3, 0.5, 1.0, 2.0, 3.0]
        ax.xaxis.set_major_locator(FixedLocator(ticks))
        ax.xaxis.set_minor_locator(NullLocator())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xticklabels([f"{t:g}" for t in ticks])
        ax.set_xlabel("us per point, this sum only (1e5 points, one BLAS thread)")
        ax.set_ylabel(f"largest change of the {what} exponent")
        ax.set_title(f"{what}: tensor trains at 3 truncations; solid: sampled max,\n"
                     "dashed: bound over the box; dotted: the shipped form's cost (no change)",
                     fontsize=9)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].legend(fontsize=7, loc="center right")
    lv = list(out["end_to_end"].values())
    est = ", ".join(f"{v['s_per_point'] * 1e6:.1f}" for v in lv[1:])
    fig.suptitle("calibrated-capillary, sphere pairs with two contact angles: force_star "
                 f"{lv[0]['s_per_point'] * 1e6:.1f} us a point as shipped,\n"
                 f"{est} us with trains (finest to coarsest truncation); goal 1 us",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(RESULTS / "pair_tt.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
