"""Error table: viscous closures against the axisymmetric Stokes FEM reference.

Two studies, both for a sphere approaching a wall (R = 1 mm, eta = 1 mPa s, v = 0.1 m/s;
the relative errors do not depend on these by linearity):

* **immersed**, S/R in [1e-4, 10]: the FEM (``stokes``) against Brenner's exact series (its
  own accuracy), and the Reynolds closure, the Cox-Brenner inner expansion and, when it is
  registered, the level-1 ``lubrication`` model against the FEM;
* **film** of thickness delta (flat free surface outside the sphere), S/delta in [0.01, 0.9]
  at delta/R = 0.01, plus the limit delta/R -> 0 at S/delta = 0.5: the Reynolds closure, the
  finite-liquid closure ``reynolds-finite`` (factor (1 - S/delta)^2, Pitois et al. 2000) and
  ``lubrication`` against the FEM;
* **bridge** between the sphere and the wall, V/R^3 = 1e-3, contact angle 20 deg on both
  solids, Navier slip 1 nm on both (the model's default), S/R in [1e-4, 1e-2]: the
  quasi-static Stokes bridge (static meniscus, moving contact lines) against which
  ``reynolds-finite`` and ``lubrication`` are measured; their error is mostly the
  contact-line dissipation they leave out (benchmarks/bench_stokes.py --part bridge).

Error = closure / FEM - 1 (the signed error of :func:`wetcontact.compare.compare`).
``points(ctx)`` is the study; ``section(out, result, ctx)`` writes ``stokes_errors.csv``
into ``out`` and returns the Markdown section. The FEM uses the ``default`` preset (``fast`` with
``quick``); the accurate sweep is in ``benchmarks/bench_stokes.py``.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.compare import compare
from wetcontact.models import ForceCurve, get_model
from wetcontact.scene import Scene, scene_from_dict
from wetcontact.sweep import Point, SweepResult
from wetcontact.tables import StudyContext

R, ETA, V = 1.0e-3, 1.0e-3, 0.1
CLOSURES = ("reynolds", "cox-brenner", "reynolds-finite", "lubrication")


BRIDGE_V, BRIDGE_THETA, BRIDGE_SLIP = 1.0e-3, 20.0, 1.0e-9


def _scene(gaps: list[float], film: float | None = None,
           volume: float | None = None) -> Scene:
    liquid: dict[str, Any] = {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0}
    if volume is not None:
        liquid |= {"contact_angle": BRIDGE_THETA, "slip_length_sphere": BRIDGE_SLIP,
                   "slip_length_wall": BRIDGE_SLIP}
        name, amount = f"stokes-table-bridge-{volume / R**3:g}", {"bridge_volume": volume}
    elif film is not None:
        name, amount = f"stokes-table-film-{film:g}", {"film_thickness": film}
    else:
        name, amount = "stokes-table", {"immersed": True}
    return scene_from_dict({
        "name": name, "geometry": {"kind": "sphere-wall", "radius": R}, "liquid": liquid,
        "amount": amount, "motion": {"velocity": V, "gaps": gaps},
    })


def _studies(quick: bool) -> list[tuple[str, float | None, list[float], Scene]]:
    """(case, delta/R or None, S/R or S/delta values, scene) of both studies."""
    s_imm = [1e-3, 0.1, 1.0] if quick else [1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0]
    out: list[tuple[str, float | None, list[float], Scene]] = [
        ("immersed", None, s_imm, _scene([s * R for s in s_imm]))]
    ratios = [0.1, 0.5, 0.9] if quick else [0.01, 0.1, 0.3, 0.5, 0.7, 0.9]
    studies = [(0.01, ratios)] + [(d, [0.5]) for d in ([0.04] if quick else [0.1, 0.03, 0.003])]
    for d, rs in studies:
        out.append(("film", d, rs, _scene([r * d * R for r in rs], film=d * R)))
    s_br = [1e-3, 1e-2] if quick else [1e-4, 1e-3, 1e-2]
    out.append(("bridge", None, s_br, _scene([s * R for s in s_br],
                                             volume=BRIDGE_V * R**3)))
    return out


def _preset(ctx: StudyContext) -> str:
    return "fast" if ctx.quick else "default"


def _closure_points(scene: Scene) -> dict[str, Point]:
    """Each closure on the gaps of ``scene`` it applies to: all of them, or those it accepts
    one by one (``cox-brenner`` refuses the immersed scene for its S/R = 10 alone, and
    would otherwise show n/a at every gap); a closure that accepts no gap is shown n/a."""
    out = {}
    for c in CLOSURES:
        model = get_model(c)
        if model.applicable(scene) is None:
            out[c] = Point(scene, c)
            continue
        ok = [g for g in scene.gaps if model.applicable(scene.with_gaps([g])) is None]
        if ok:
            out[c] = Point(scene.with_gaps(ok), c)
    return out


def _on_gaps(curve: ForceCurve, gaps: np.ndarray) -> ForceCurve:
    """``curve``'s viscous force at ``gaps`` (a subset of its own), for :func:`compare`."""
    idx = np.array([int(np.flatnonzero(curve.gap == g)[0]) for g in gaps], dtype=int)
    return ForceCurve(case=curve.case, model=curve.model, gap=curve.gap[idx],
                      force_viscous=curve.force_viscous[idx], force_capillary=None)


def points(ctx: StudyContext) -> list[Point]:
    """The FEM, Brenner's series (immersed) and every applicable closure on each scene."""
    pts = []
    for case, _, _, sc in _studies(ctx.quick):
        pts.append(Point(sc, "stokes", _preset(ctx)))
        if case == "immersed":
            pts.append(Point(sc, "brenner"))
        pts.extend(_closure_points(sc).values())
    return pts


def _errors(result: SweepResult, sc: Scene, fem: Any) -> dict[str, Any]:
    """Closure name -> its comparison with the FEM (None: refused or failed)."""
    out = {}
    for c in CLOSURES:
        p = _closure_points(sc).get(c)
        curve = None if p is None else result.curve(p)
        out[c] = None if curve is None else compare(
            curve, fem if curve.gap.size == fem.gap.size else _on_gaps(fem, curve.gap),
            "viscous")
    return out


def _signed(rec: Any, gap: float) -> float:
    return float("nan") if rec is None else rec.signed_at(gap)


def _fmt(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:+.2e}"


def section(out: Path, result: SweepResult, ctx: StudyContext) -> str:
    """Write ``stokes_errors.csv`` into ``out`` and return the Markdown section."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    preset = _preset(ctx)
    rows: list[dict[str, Any]] = []
    for case, d, ratios, sc in _studies(ctx.quick):
        fem = result.curve(Point(sc, "stokes", preset))
        if fem is None:
            continue
        errs = _errors(result, sc, fem)
        exact = None
        if case == "immersed":
            ref = result.curve(Point(sc, "brenner"))
            exact = None if ref is None else compare(fem, ref, "viscous")
        for i, r in enumerate(ratios):
            g = fem.gap[i]
            rows.append({"case": case if case != "bridge" else
                         f"bridge V/R^3 = {BRIDGE_V:g}",
                         "s_over_r": r if d is None else r * d,
                         "delta_over_r": "" if d is None else d,
                         "s_over_delta": "" if d is None else r,
                         "force_fem_N": fem.force_viscous[i],
                         "fem_vs_exact": _signed(exact, g),
                         **{f"err_{c}": _signed(errs[c], g) for c in CLOSURES}})

    path = out / "stokes_errors.csv"
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.8e}" if isinstance(v, float) else v) for k, v in row.items()})

    lines = [
        "## Viscous closures against the Stokes FEM",
        "",
        f"Sphere approaching a wall; error = closure / FEM - 1; FEM preset `{preset}` "
        f"(its own error against Brenner's exact series in the first column). "
        f"CSV: `{path.name}`.",
        "",
        "| case | S/R | delta/R | S/delta | FEM vs exact | Reynolds | Cox-Brenner | "
        "(1-S/H)^2 finite liquid | lubrication |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        dr = "" if row["delta_over_r"] == "" else f"{row['delta_over_r']:g}"
        sd = "" if row["s_over_delta"] == "" else f"{row['s_over_delta']:g}"
        lines.append(
            f"| {row['case']} | {row['s_over_r']:.3g} | {dr} | {sd} | "
            f"{_fmt(row['fem_vs_exact'])} | {_fmt(row['err_reynolds'])} | "
            f"{_fmt(row['err_cox-brenner'])} | {_fmt(row['err_reynolds-finite'])} | "
            f"{_fmt(row['err_lubrication'])} |")
    imm = [r for r in rows if r["case"] == "immersed"]
    worst = max(abs(r["err_reynolds"]) for r in imm if r["s_over_r"] <= 0.1)
    film = [r for r in rows if r["case"] == "film" and r["delta_over_r"] == 0.01]
    fl = [abs(r["err_reynolds-finite"]) for r in film if np.isfinite(r["err_reynolds-finite"])]
    bridge = [r for r in rows if r["case"].startswith("bridge")]
    if bridge:
        lub = [r["err_lubrication"] for r in bridge]
        lines += ["", (f"Bridge (sphere-wall, {BRIDGE_THETA:g} deg, slip {BRIDGE_SLIP:g} m, "
                       "the FEM's quasi-static meniscus): `lubrication` is "
                       + ", ".join(f"{100 * e:+.1f} %" for e in lub) + " off at S/R = "
                       + ", ".join(f"{r['s_over_r']:g}" for r in bridge) + "; the "
                       "difference is mostly the dissipation of the two moving contact "
                       "lines (Huh-Scriven, ~ ln(1/slip)), which the closures leave out: it "
                       "stays nearly constant while the film force grows like 1/S.")]
    lines += ["", (f"Immersed: the Reynolds closure is within {100 * worst:.1f} % of the FEM for "
                   f"S/R <= 0.1 and fails beyond; in a film (delta/R = 0.01) the finite-liquid "
                   f"factor stays within {100 * max(fl):.0f} % of the FEM over S/delta in "
                   f"[{film[0]['s_over_delta']:g}, {film[-1]['s_over_delta']:g}].") if fl else
              f"Immersed: Reynolds within {100 * worst:.1f} % for S/R <= 0.1."]
    return "\n".join(lines) + "\n"
