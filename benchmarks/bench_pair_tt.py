"""The two-angle sphere-pair table in tensor-train form: cost and accuracy against its fit.

The ``calibrated-capillary`` table for sphere pairs with two contact angles is fitted as
Chebyshev tables per piece: a dense rupture table over (w, a, b1, b2) and a rank-r force
table ``sum_k L_k(w, a, b1) R_k(b2, c)``. What ships and is evaluated is each table's
tensor train (TT-SVD, Oseledets 2011, SIAM J. Sci. Comput. 33, 2295:
``C_{i1..id} ~ G1[i1] ... Gd[id]``, ``calibrated_capillary.train_piece`` at ``TRAIN_TOL``),
one batched matrix product per core (``calibrated_capillary.train_sum``). This benchmark
compares, in one run, the fit itself (the pieces without their trains), the shipped
trains and trains at a finer and a coarser truncation:

- cost: ``force_star`` per point on 1e5 two-angle pair points drawn as ``bench_calibrate``'s (one
  BLAS thread, median of 5), and each piece's multiply-adds a point;
- change: the largest relative change of the force (where both forms give a bridge) and
  of the rupture distance on those points, against the fit;
- accuracy: the table's held-out maxima per stratum (``calibrated_capillary_pairs.pair_held_out``:
  500 bridges, 4000 force points, against fresh ``meniscus``; cached in the node cache
  after the first run, about 1 minute from an empty cache) with each form;
- probe change: each train's largest change of its table's sum against the fit on the
  probe on which ``calibrated_capillary.factor_table`` chose the force factors' rank (the
  table's Chebyshev-Lobatto grid and 20 000 seeded uniform points): everywhere, and off
  the gap axis's rupture end (c = -1, S -> S_c, where the force's dependence on S_c is a
  square root's, and which no held-out point reaches: they stop at 0.999 S_c).

A fifth form holds each train to a bound on that probe (:data:`HELD`: the force factors'
own standard, 5e-5, and 5e-6 for the rupture distance): its axis order is the
cheapest at the TT-SVD tolerance that first meets the bound (halving from 1e-5), and its
ranks are then lowered one at a time, the largest saving of multiply-adds first, while
the bound holds. It shows what the shipped truncation trades for its cost.

Writes ``benchmarks/results/pair_tt.json`` and ``pair_tt.png``. Run:
``python benchmarks/bench_pair_tt.py`` (about 6 minutes from an empty node cache).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

# one BLAS thread before numpy loads, as bench_calibrate's per-point costs
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, median_time, write_json  # noqa: E402

from wetcontact.generate import calibrated_capillary as gen  # noqa: E402
from wetcontact.generate import calibrated_capillary_pairs as p2  # noqa: E402
from wetcontact.reduced_models import calibrated_capillary as cc  # noqa: E402

N = 100_000
VARIANTS = {"finer trains": (1e-7, 3e-6), "coarser trains": (1e-5, 3e-5)}
"""Truncations (rupture, force) compared with the shipped :data:`calibrated_capillary.TRAIN_TOL`."""
HELD = {"rupture_train": 5e-6, "force_train": gen.FACTOR_TOL}
"""The held trains' bound on the probe: the force factors' own standard, 5 % of the 1e-3
force goal (:data:`~wetcontact.generate.calibrated_capillary.FACTOR_TOL`), and 1 % of the 5e-4
rupture goal: S_c sets the force's gap coordinate, on which the force depends as a square
root near S_c (held to 2.5e-5, 5 % of its goal, the rupture trains moved the force by
2.7e-4 on the cost points, against 1.1e-4 with the shipped trains)."""
PROBE_UNIFORM = 20_000


def grid_values(coef: np.ndarray) -> np.ndarray:
    """A tensor Chebyshev sum's values on the Chebyshev-Lobatto grid of its shape (one
    matrix ``T_j(x_i)`` applied along each axis)."""
    out = coef
    for ax, n in enumerate(coef.shape):
        t = cc._cheb_rows(gen.lobatto(n), n).T  # (point, degree)
        out = np.moveaxis(np.tensordot(out, t, axes=([ax], [1])), -1, ax)
    return out


def probe(coef: np.ndarray, seed: int = 0) -> Any:
    """The largest change of a train's sum against ``coef``'s on the probe (module
    docstring): a function of a train, returning (everywhere, off the rupture end)."""
    rng = np.random.default_rng(seed)
    grid = grid_values(coef)
    x = [rng.uniform(-1.0, 1.0, PROBE_UNIFORM) for _ in coef.shape]
    rows = [cc._cheb_rows(xi, m) for xi, m in zip(x, coef.shape, strict=True)]
    ref = cc.chebyshev_tensor(coef, x)
    gap_axis = coef.ndim == 5  # the force table's last axis is the gap coordinate c

    def change(train: dict[str, Any]) -> tuple[float, float]:
        d = np.abs(grid_values(cc.train_dense(train["cores"], train["order"])) - grid)
        u = float(np.max(np.abs(cc.train_sum(train, rows) - ref)))
        off = d[..., 1:] if gap_axis else d  # lobatto(n)[0] = -1: the rupture end
        return max(float(d.max()), u), max(float(off.max()), u)
    return change


def _train(coef: np.ndarray, order: list[int], tol: float,
           ranks: list[int] | None = None) -> dict[str, Any]:
    cores = gen.tt_svd(coef.transpose(order), tol, ranks)
    return {"order": list(order), "ranks": [g.shape[2] for g in cores[:-1]], "cores": cores}


def held_train(coef: np.ndarray, bound: float) -> dict[str, Any]:
    """A train of ``coef`` whose sum changes by at most ``bound`` on the probe, with few
    multiply-adds a point (module docstring: tolerance halved from 1e-5 until the bound
    holds, then ranks lowered greedily)."""
    change = probe(coef)
    tol = 1e-5
    order = gen.train_of(coef, tol)["order"]
    train = _train(coef, order, tol)
    while change(train)[0] > bound:
        tol /= 2.0
        order = gen.train_of(coef, tol)["order"]
        train = _train(coef, order, tol)
    while True:
        trials = [_train(coef, order, 0.0, [r - (i == k) for i, r in enumerate(train["ranks"])])
                  for k in range(len(train["ranks"])) if train["ranks"][k] > 1]
        trials = [t for t in trials if change(t)[0] <= bound]
        if not trials:
            return {**train, "tol": f"probe change <= {bound:g}"}
        train = min(trials, key=lambda t: sum(g.size for g in t["cores"]))


def variant(entry: dict[str, Any], tols: tuple[float, float] | str | None
            ) -> dict[str, Any]:
    """The table with its pieces' trains rebuilt at ``tols`` (rupture, force), or held to
    :data:`HELD` on the probe (``"held"``, :func:`held_train`), or without trains
    (``None``: the fit, its rupture tables and low-rank force factors)."""
    def piece(p: dict[str, Any]) -> dict[str, Any]:
        fit = {k: v for k, v in p.items() if k not in cc.TRAIN_FIELDS}
        if tols is None:
            return fit
        if tols == "held":
            return {**fit, **{k: held_train(c, HELD[k]) for k, c in gen.train_fits(p).items()}}
        return {**fit, **{k: gen.train_of(c, t)
                          for (k, c), t in zip(gen.train_fits(p).items(), tols, strict=True)}}
    out = {**entry, "bands": [{**b, "pieces": [piece(p) for p in b["pieces"]]}
                              for b in entry["bands"]]}
    return cc.as_arrays({"e": out})["e"]


def points() -> tuple[np.ndarray, ...]:
    """1e5 two-angle pair points drawn as ``bench_calibrate`` draws its own (the same
    distributions and seed, not the same draws: that benchmark draws other inputs first)."""
    rng = np.random.default_rng(1)
    v = np.exp(rng.uniform(np.log(1e-4), np.log(0.1), N))
    th = np.radians(rng.uniform(0, 70, N))
    ratio = np.exp(rng.uniform(0, np.log(10), N))
    tw = np.radians(rng.uniform(0, 70, N))
    _, sc = cc.force_star("sphere-sphere", v, th, np.zeros(N), ratio, theta_wall=tw)
    return v, th, rng.uniform(0, 1.0, N) * sc, ratio, tw


def measure(entry: dict[str, Any], pts: tuple[np.ndarray, ...]) -> dict[str, Any]:
    """Cost a point, the values at the points, held-out maxima and per-piece work."""
    v, th, gap, ratio, tw = pts
    t, (f, sc) = median_time(lambda: cc.force_star(cc.PAIR_TWO_ANGLES, v, th, gap, ratio,
                                                   entry=entry, theta_wall=tw), repeats=5)
    pieces = []
    for b, band in enumerate(entry["bands"]):
        for i, p in enumerate(band["pieces"]):
            rec = {"band": b, "piece": "upper" if i else "lower"}
            if "force_train" in p:
                for n, coef in gen.train_fits(p).items():
                    everywhere, off_end = probe(coef)(p[n])
                    rec[n] = {"order": list(p[n]["order"]), "ranks": list(p[n]["ranks"]),
                              "macs": int(sum(g.size for g in p[n]["cores"])),
                              "probe_change": everywhere,
                              "probe_change_off_rupture_end": off_end}
            else:
                left, right = p["force_left"], p["force_right"]
                rec["rupture_macs"] = int(p["rupture"].size)
                rec["force_macs"] = int(left.shape[-1] * (left[..., 0].size + right[0].size))
            pieces.append(rec)
    held = {k: {q: h[q]["max"] for q in ("rupture_distance", "force")}
            for k, h in p2.pair_held_out(entry, 120, 2).items()}
    return {"s_per_point": t / N, "held_out_max": held, "pieces": pieces, "_values": (f, sc)}


def shipped_pair_table(script: str) -> dict[str, Any]:
    """The package data's two-angle sphere-pair table (exits naming ``script`` without)."""
    table = cc.capillary_table()
    if table is None or cc.PAIR_TWO_ANGLES not in table:
        sys.exit(f"{script}: the package data has no two-angle sphere-pair table")
    return table[cc.PAIR_TWO_ANGLES]


def main() -> None:
    shipped = shipped_pair_table("bench_pair_tt")
    pts = points()
    forms = {"fit (no trains)": variant(shipped, None),
             f"finer trains {VARIANTS['finer trains']}": variant(shipped,
                                                                  VARIANTS["finer trains"]),
             "shipped trains "
             f"{(gen.TRAIN_TOL['rupture_train'], gen.TRAIN_TOL['force_train'])}": shipped,
             f"coarser trains {VARIANTS['coarser trains']}": variant(
                 shipped, VARIANTS["coarser trains"]),
             "trains held on the probe (5e-6, 5e-5)": variant(shipped, "held")}
    out: dict[str, Any] = {}
    for name, entry in forms.items():
        out[name] = measure(entry, pts)
        print(f"{name}: {out[name]['s_per_point'] * 1e6:.2f} us a point", flush=True)
    f0, sc0 = out["fit (no trains)"]["_values"]
    for rec in out.values():
        f, sc = rec.pop("_values")
        both = (f > 0) & (f0 > 0)
        rec["max_change_force_vs_fit"] = float(np.max(np.abs(f[both] / f0[both] - 1.0)))
        rec["max_change_rupture_vs_fit"] = float(np.max(np.abs(sc / sc0 - 1.0)))
    fit_held = out["fit (no trains)"]["held_out_max"]
    for rec in out.values():
        rec["held_out_max_change_vs_fit"] = max(
            abs(m - fit_held[k][q]) for k, h in rec["held_out_max"].items()
            for q, m in h.items())
    result = {"points": N, "blas_threads": os.environ["OPENBLAS_NUM_THREADS"],
              "forms": out}
    write_json("pair_tt", result)
    chart(result)
    print(json.dumps({k: {q: v[q] for q in ("s_per_point", "max_change_force_vs_fit",
                                            "max_change_rupture_vs_fit",
                                            "held_out_max_change_vs_fit")}
                      for k, v in out.items()}, indent=1))


def probe_worst(form: dict[str, Any]) -> float | None:
    """A form's largest force-train change on the probe off the rupture end (None: no
    trains)."""
    got = [p["force_train"]["probe_change_off_rupture_end"] for p in form["pieces"]
           if "force_train" in p]
    return max(got) if got else None


def chart(result: dict[str, Any]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    forms = result["forms"]
    names = list(forms)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11.5, 4.6),
                                   gridspec_kw={"width_ratios": [1, 1.5]})
    cost = [forms[n]["s_per_point"] * 1e6 for n in names]
    ax0.barh(names, cost, color=[f"C{i}" for i in range(len(names))])
    for y, (c, n) in enumerate(zip(cost, names, strict=True)):
        worst = probe_worst(forms[n])
        ax0.text(c, y, f" {c:.2f}" + ("" if worst is None else
                                      f"\n force probe change {worst:.1e} (S < S_c)"),
                 va="center", fontsize=7)
    ax0.axvline(1.0, color="k", ls="--", lw=1.0, label="goal, 1 us")
    ax0.set_xlabel("us per point (force_star, 1e5 points, one BLAS thread)")
    ax0.set_xlim(0, max(cost) * 1.6)
    ax0.invert_yaxis()
    ax0.legend(fontsize=8, loc="lower right")
    ax0.set_title("evaluation cost", fontsize=10)
    strata = list(forms[names[0]]["held_out_max"])
    x = np.arange(len(strata))
    width = 0.8 / len(names)
    hatches = ["", "//", "..", "xx", "\\\\"]
    for i, n in enumerate(names):
        ax1.bar(x + (i - (len(names) - 1) / 2) * width,
                [forms[n]["held_out_max"][s]["force"] for s in strata], width,
                color=f"C{i}", hatch=hatches[i], edgecolor="k", lw=0.4, label=n)
    ax1.axhline(1e-3, color="k", ls="--", lw=1.0, label="force goal, 1e-3")
    ax1.set_xticks(x)
    ax1.set_xticklabels([s.replace("held_out_", "").replace("held_out", "uniform")
                         .replace("_", " ") for s in strata], fontsize=8)
    ax1.set_yscale("log")
    ax1.set_ylabel("held-out max relative force error\n(against fresh meniscus)")
    ax1.legend(fontsize=7, loc="upper left")
    ax1.set_title("accuracy per held-out stratum", fontsize=10)
    fig.suptitle("calibrated-capillary, sphere pairs with two contact angles: the fit "
                 "vs its tensor trains", fontsize=10)
    fig.tight_layout()
    fig.savefig(RESULTS / "pair_tt.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
