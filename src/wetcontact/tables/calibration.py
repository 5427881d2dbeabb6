"""Held-out error tables of the refitted closure families and the shipped calibrated closures.

Renders from calibration outputs, never solving: each family's JSON written by
``wetcontact calibrate`` (:func:`wetcontact.calibrate.write_calibration`; the committed ones
are ``benchmarks/results/calibration/*.json``) and the ``calibrated-viscous`` and
``calibrated-capillary`` closures' package data (``reduced_models/data/calibrated_*.json``),
named in the
:class:`~wetcontact.tables.StudyContext` by ``wetcontact run``.

For each family: the relative error ``|F_closure / F_reference - 1|`` on the held-out points
(a seeded design the fit never saw) with the published coefficients and with the refitted
ones (maximum, mean, 95th percentile, where the refitted maximum sits), the ratio of the
maxima and whether the goal of issue 11 holds (refitted maximum at most 1/3 of the
published one), and the domain the coefficients are valid on. ``calibration_heldout.csv``
holds one row per (closure, part, coefficients).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from wetcontact.errors import InputError
from wetcontact.reduced_models.calibrated_capillary import table_pieces
from wetcontact.sweep import Point, SweepResult
from wetcontact.tables import StudyContext

CSV_NAME = "calibration_heldout.csv"
FIELDS = ("closure", "part", "coefficients", "reference", "points", "seed", "max", "mean",
          "p95", "max_at", "goal", "goal_met", "domain", "source")
VISCOUS_GOALS = {"immersed": 5e-4, "film": 1e-2, "bridge": 1e-2}
"""Issue 11's held-out goals of ``calibrated-viscous``: 5e-4 of the exact series
(immersed), 1 % of the best reference (films and bridges)."""


def load_calibrations(folder: str | Path) -> tuple[tuple[str, dict[str, Any]], ...]:
    """``(path, data)`` of every calibration JSON in ``folder`` (sorted by name); a file
    that is not a calibration output is an :class:`InputError` naming it."""
    out = []
    for path in sorted(Path(folder).glob("*.json")):
        data = load_json(path)
        for key in ("family", "held_out", "domain"):
            if key not in data:
                raise InputError(f"{path}: field '{key}' missing; allowed: a JSON written "
                                 "by wetcontact calibrate")
        out.append((str(path), data))
    return tuple(out)


def load_json(path: str | Path) -> dict[str, Any]:
    """A JSON object from ``path`` (an :class:`InputError` naming the file otherwise)."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a readable calibration JSON ({exc})") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: allowed: a JSON object")
    return data


def points(ctx: StudyContext) -> list[Point]:
    """Nothing to sweep: the tables come from the calibration outputs."""
    return []


def _where(at: dict[str, float]) -> str:
    return ", ".join(f"{k} {v:.3g}" for k, v in at.items() if v is not None)


def _domain(dom: dict[str, Any]) -> str:
    return ", ".join(f"{k} [{lo:.3g}, {hi:.3g}]" for k, (lo, hi) in dom.items())


def _mmp(e: dict[str, Any]) -> str:
    return f"{e['max']:.3g} / {e['mean']:.3g} / {e['p95']:.3g}"


def family_rows(path: str, data: dict[str, Any]) -> list[dict[str, Any]]:
    """Two CSV rows (published, refitted) of one family's calibration JSON."""
    ho = data["held_out"]
    goal = ho["after"]["max"] <= ho["before"]["max"] / 3.0
    return [{"closure": data["family"], "part": data.get("target", ""), "coefficients": tag,
             "reference": data.get("reference", ""), "points": ho["points"],
             "seed": ho.get("seed"), "max": ho[k]["max"], "mean": ho[k]["mean"],
             "p95": ho[k]["p95"], "max_at": _where(ho[k].get("max_at", {})),
             "goal": "refit max <= published max / 3" if tag == "refitted" else "",
             "goal_met": goal if tag == "refitted" else "", "domain": _domain(data["domain"]),
             "source": path}
            for tag, k in (("published", "before"), ("refitted", "after"))]


def viscous_rows(path: str, data: dict[str, Any]) -> list[dict[str, Any]]:
    """CSV rows of the shipped ``calibrated-viscous`` closure's held-out tables."""
    rows = []
    for kind, t in data.get("immersed", {}).items():
        ho = t["held_out"]
        lo, hi = t["log_range"]
        rows.append({"closure": "calibrated-viscous", "part": f"immersed {kind}",
                     "coefficients": "shipped", "reference": ho.get("reference", ""),
                     "points": ho["points"], "seed": ho.get("seed"), "max": ho["max"],
                     "mean": ho["mean"], "p95": ho["p95"],
                     "max_at": f"s_over_r {ho['max_at_s_over_r']:.3g}",
                     "goal": VISCOUS_GOALS["immersed"],
                     "goal_met": ho["max"] <= VISCOUS_GOALS["immersed"],
                     "domain": f"s_over_r [{2.718281828459045 ** lo:.3g}, "
                               f"{2.718281828459045 ** hi:.3g}]", "source": path})
    parts = [("film", data["film"])] if "film" in data else []
    parts += [(f"bridge {k}", v) for k, v in data.get("bridge", {}).items()]
    for part, t in parts:
        ho = t["held_out"]
        goal = VISCOUS_GOALS[part.split()[0]]
        for tag, k in (("Pitois (1 - S/H)^2", "before"), ("shipped", "after")):
            shipped = tag == "shipped"
            rows.append({"closure": "calibrated-viscous", "part": part, "coefficients": tag,
                         "reference": t.get("reference", ""), "points": ho["points"],
                         "seed": ho.get("seed"), "max": ho[k]["max"], "mean": ho[k]["mean"],
                         "p95": ho[k]["p95"], "max_at": _where(ho[k].get("max_at", {})),
                         "goal": goal if shipped else "",
                         "goal_met": ho[k]["max"] <= goal if shipped else "",
                         "domain": _domain(t["domain"]), "source": path})
    return rows


TWO_ANGLES = "sphere-wall-two-angles"
"""The wall table with two contact angles (``calibrated_capillary.WALL_TWO_ANGLES``; the
report reads data, not the model)."""
PAIR_TWO_ANGLES = "sphere-sphere-two-angles"
"""The sphere-pair table with two contact angles (``calibrated_capillary.PAIR_TWO_ANGLES``)."""
CAPILLARY_KINDS = ("sphere-wall", TWO_ANGLES, "sphere-sphere", PAIR_TWO_ANGLES)
ANGLES_TEXT = {TWO_ANGLES: ", the sphere's and the wall's angle each in the theta range",
               PAIR_TWO_ANGLES: ", the small sphere's and the large sphere's angle each in "
                                "the theta range"}
"""The domain's angle clause per table (default: one contact angle on both solids)."""


def capillary_rows(path: str, data: dict[str, Any]) -> list[dict[str, Any]]:
    """CSV rows of the shipped ``calibrated-capillary`` closure's held-out tables (rupture
    distance and force, per kind)."""
    goals = data.get("goals", {"force": 1e-3, "rupture_distance": 5e-4})
    dom = dict(data.get("domain", {}))
    rows = []
    for kind in CAPILLARY_KINDS:
        if "held_out" not in data.get(kind, {}):
            continue
        for key, label in (("held_out", ""), ("held_out_near_equal", " (nearly equal)"),
                           ("held_out_near_ridge", " (near the ridge)"),
                           ("held_out_ridge_top", " (at the ridge top)"),
                           ("held_out_ridge_onset", " (at the ridge top where its jump "
                                                    "appears)"),
                           ("held_out_ridge_onset_rupture", " (at the ridge top where its "
                                                            "jump appears, gaps to 0.999 S_c)"),
                           ("held_out_ridge_window", " (within the ridge series' error of "
                                                     "the ridge, gaps to 0.999 S_c)"),
                           ("held_out_low_angles", " (both angles 0-15 deg, V* 0.01-0.1, "
                                                   "gaps to 0.999 S_c)"),
                           ("held_out_corners", " (domain corners, edges and middle, "
                                                "gaps to 0.999 S_c)")):
            if key not in data[kind]:
                continue
            ho = data[kind][key]
            d = {k: v for k, v in {**dom, **ho.get("stratum", {})}.items()
                 if kind.startswith("sphere-sphere") or k != "radius_ratio"}
            angles = ANGLES_TEXT.get(kind, ", one contact angle on both solids")
            parts = [(p, p) for p in ("rupture_distance", "force")]
            if "force_attached" in ho and ho["force_attached"]["max"] != ho["force"]["max"]:
                # the force's jump to 0 short of the true S_c dominates "force"
                parts.append(("force_attached", "force where the closure's bridge exists"))
            for part, name in parts:
                e = ho[part]
                goal = goals["force" if part == "force_attached" else part]
                rows.append({"closure": "calibrated-capillary",
                             "part": f"{kind}{label} {name}", "coefficients": "shipped",
                             "reference": ho.get("reference", ""), "points": e["points"],
                             "seed": ho.get("seed"), "max": e["max"], "mean": e["mean"],
                             "p95": e["p95"], "max_at": _where(e["max_at"]),
                             "goal": goal, "goal_met": e["max"] <= goal,
                             "domain": _domain(d) + angles, "source": path})
    return rows


def section(out: Path, result: SweepResult, ctx: StudyContext) -> str:
    """Write ``calibration_heldout.csv`` into ``out``; return the Markdown section."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    md = ["## Calibration: held-out errors of refitted and calibrated closures", "",
          "Relative error |closure/reference - 1| on held-out points, a seeded design the "
          "fit never saw (`wetcontact calibrate STUDY --closure FAMILY`; studies "
          "`cases/studies/calibrate-*.toml`). Goal (issue 11): refitted maximum at most 1/3 "
          f"of the published one on the same points. Data: [{CSV_NAME}]({CSV_NAME}).", ""]
    rows: list[dict[str, Any]] = []
    if ctx.calibration:
        md += ["| family | reference | held-out points | published max / mean / p95 | "
               "refitted max / mean / p95 | refit / published | 1/3 goal | refitted max at | "
               "domain |", "|---|---|---|---|---|---|---|---|---|"]
        for path, data in ctx.calibration:
            ho = data["held_out"]
            fr = family_rows(path, data)
            rows += fr
            b, a = ho["before"], ho["after"]
            ratio = a["max"] / b["max"] if b["max"] > 0 else float("inf")
            md.append(f"| `{data['family']}` | {data.get('reference', '')} | {ho['points']} | "
                      f"{_mmp(b)} | {_mmp(a)} | {ratio:.2f} | "
                      f"{'met' if fr[1]['goal_met'] else '**not met**'} | "
                      f"{_where(a.get('max_at', {}))} | {_domain(data['domain'])} |")
        md += ["", "Sources: " + ", ".join(f"`{p}`" for p, _ in ctx.calibration) + "."]
    else:
        md.append("No calibration output was given (`benchmarks/results/calibration/`).")
    md += ["", "### Shipped closure `calibrated-viscous`", ""]
    cv = ctx.calibrated_viscous
    if cv is not None:
        vr = viscous_rows(ctx.calibrated_viscous_path, cv)
        rows += vr
        md += ["| part | coefficients | reference | held-out points | max / mean / p95 | "
               "goal (max) | max at | domain |", "|---|---|---|---|---|---|---|---|"]
        md += [f"| {r['part']} | {r['coefficients']} | {r['reference'].split(':')[0]} | "
               f"{r['points']} | {_mmp(r)} | "
               + (f"{r['goal']:g}: {'met' if r['goal_met'] else '**not met**'}"
                  if r["goal"] != "" else "") + f" | {r['max_at']} | {r['domain']} |"
               for r in vr]
        md += ["", f"Source: `{ctx.calibrated_viscous_path}` "
               f"(`{cv.get('generated_by', 'python -m wetcontact.generate calibrated-viscous')}`)."]
    else:
        md.append("Its table was not given.")
    md += ["", "### Shipped closure `calibrated-capillary`", ""]
    ccap = ctx.calibrated_capillary
    if ccap is not None:
        cr = capillary_rows(ctx.calibrated_capillary_path, ccap)
        rows += cr
        md += ["Tensor Chebyshev interpolation of `meniscus` (force and rupture distance): "
               "one contact angle on both solids, and on a wall also two independent angles "
               f"(`{TWO_ANGLES}`: the sphere's angle, and the wall's in two pieces that meet "
               "at the ridge where the rupture distance peaks)"
               + (f", and between spheres (`{PAIR_TWO_ANGLES}`: the small sphere's angle, "
                  "and the large one's in two pieces that meet at the ridge)"
                  if PAIR_TWO_ANGLES in ccap else "")
               + "; held-out bridges are seeded "
               "and off the nodes, gaps uniform in [0, 0.999] S_c. The corner strata "
               "(`python -m wetcontact.generate calibrated-capillary --corners`) are not seeded: "
               "every combination of both ends and the middle of V*, of each angle and of "
               "the radius ratio, at S/S_c = 1e-6, 0.5, 0.9, 0.99 and 0.999, where a "
               "uniform design seldom lands. Toward rupture the error of S_c is amplified "
               "by the fold's square root, so the force's corner maxima sit at 0.999 S_c.",
               "",
               "| part | reference | held-out points | max / mean / p95 | goal (max) | max at "
               "| domain |", "|---|---|---|---|---|---|---|"]
        md += [f"| {r['part']} | {r['reference']} | {r['points']} | {_mmp(r)} | "
               f"{r['goal']:g}: {'met' if r['goal_met'] else '**not met**'} | {r['max_at']} | "
               f"{r['domain']} |" for r in cr]
        br = ccap.get("branches") or {}
        reused = (f", {br['reused']} of {br['reused'] + br['solved']} meniscus branches "
                  "reused from its cache" if br.get("reused") else "")
        pieces = {k: table_pieces(ccap[k]) for k in CAPILLARY_KINDS if k in ccap}
        pieces = {k: ps for k, ps in pieces.items()
                  if ps and all("force_rank" in p for p in ps)}
        ranks = ", ".join(f"{k} {'/'.join(str(p['force_rank']) for p in ps)}"
                          for k, ps in pieces.items())
        change = max((p["force_factor_change"] for ps in pieces.values() for p in ps),
                     default=0.0)
        fits = ", ".join(f"{k} {ccap[k]['fit_time_s']:g} s" for k in CAPILLARY_KINDS
                         if "fit_time_s" in ccap.get(k, {}))
        md += ["", f"Source: `{ctx.calibrated_capillary_path}` (`{ccap.get('generated_by')}`, "
               f"last run {ccap.get('wall_time_s', '?')} s{reused}"
               + (f"; fit times: {fits}" if fits else "") + ")."
               + (f" Force tables in low-rank form, rank {ranks} (largest change of the "
                  f"force on the factorisation's probe {change:.1e})." if ranks else "")]
    else:
        md.append("Its table was not generated (`python -m wetcontact.generate "
                  "calibrated-capillary`).")
    if rows:
        with (out / CSV_NAME).open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(FIELDS))
            w.writeheader()
            w.writerows(rows)
    return "\n".join(md) + "\n"
