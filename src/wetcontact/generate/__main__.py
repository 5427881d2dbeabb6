"""``python -m wetcontact.generate TABLE|all [--workers N] [--dask | --scheduler ADDR]``:
rebuild the package data.

Each table command runs the generator of one shipped file (:data:`TABLES`); ``all`` runs them
in the order they depend on each other (the bound tables measure the calibrated closures
last); ``list`` names them; ``fit`` refits one closure family on its default design (a file
of your own, not package data). The capillary tables' meniscus solves run on ``--workers``
processes, or on Dask workers (:mod:`.workers`). Bad input: one line on stderr, exit 2.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from wetcontact.calibrate import FAMILIES, run_family
from wetcontact.errors import InputError
from wetcontact.generate.bounds import ALONE, DATA_PATH
from wetcontact.generate.workers import open_workers
from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import calibrated_capillary as cc

PROG = "python -m wetcontact.generate"
PAIR_KIND = cc.PAIR_TWO_ANGLES
CAPILLARY_KINDS = ("sphere-wall", "sphere-sphere", cc.WALL_TWO_ANGLES, PAIR_KIND)

TABLES: dict[str, tuple[str, str, str]] = {
    "calibrated-viscous": (
        "calibrated_viscous.json",
        "wetcontact.generate.calibrated_viscous.generate_calibrated_viscous",
        "the calibrated-viscous closure: immersed Chebyshev tables, film and bridge factors "
        "(lubrication and stokes solves, one process)"),
    "calibrated-capillary": (
        cc.CAPILLARY_FILE,
        "wetcontact.generate.calibrated_capillary.generate_calibrated_capillary; "
        "wetcontact.generate.calibrated_capillary_pairs.generate_pair_table",
        "the calibrated-capillary closure's tables, one contact angle on a wall and between "
        "spheres, two on a wall, two between spheres (meniscus solves on --workers processes)"),
    "transfer-fraction": (
        "transfer_fraction.json",
        "wetcontact.generate.transfer_fraction.generate_transfer_fraction",
        "the calibrated transfer fraction at rupture: the jump and the two side tables, "
        "held-out table in transfer_fraction_record.json (meniscus solves on --workers "
        "processes)"),
    "dynamic-rupture": (
        "dynamic_rupture.json",
        "wetcontact.generate.dynamic_rupture.generate_dynamic_rupture",
        "the dynamic rupture closure S_c(Ca)/S_c: stokes-dynamic stretching runs to the pinch "
        "over Ca, volume, angle, sphere-wall and equal spheres, fitted, with held-out runs "
        "(--workers processes)"),
    "bounds": (
        DATA_PATH.name,
        "wetcontact.generate.bounds.measure_bounds",
        "the closures' measured error-bound tables (every closure against its reference, "
        "one process; measures the calibrated closures, so it runs last)"),
}
"""Table name -> (file in ``reduced_models/data``, generator function(s), what it holds)."""


def _table_copy(out: Path | None) -> Path | None:
    """``--out`` for the capillary table commands: a copy of the package data's table file
    made there if it does not exist yet (``None``: the package data itself)."""
    if out is not None and not out.is_file():
        import shutil

        if not out.parent.is_dir():
            raise InputError(f"--out {out}: folder {out.parent} does not exist; allowed: a "
                             "file in an existing folder")
        shutil.copy(DATA_DIR / cc.CAPILLARY_FILE, out)
    return out


def _print_held_out(kind: str, entry: dict[str, Any]) -> None:
    """One line per held-out table of a capillary table's entry."""
    for key in sorted(k for k in entry if k.startswith("held_out")):
        ho = entry[key]
        print(f"{kind} {key}: max rupture {ho['rupture_distance']['max']:.3g}, "
              f"force {ho['force']['max']:.3g} ({ho['force']['points']} points)")


def _say(table: str, out: Path | None = None) -> None:
    """Which table is generated, into which file (``out``, default the package data's), by
    which function."""
    file, func, _ = TABLES[table]
    print(f"generate {table}: {out or DATA_DIR / file} ({func})", flush=True)


def _workers_unused(table: str, workers: int | None) -> None:
    if workers is not None:
        print(f"generate {table}: runs in one process (--workers {workers} not used)",
              flush=True)


def parser() -> argparse.ArgumentParser:
    """The command line (subcommands: the tables, ``all``, ``list``, ``fit``)."""
    p = argparse.ArgumentParser(prog=PROG, description="Rebuild the package data: one "
                                "table, or all of them in order.")
    sub = p.add_subparsers(dest="command", required=True, metavar="TABLE|all|list|fit")
    sub.add_parser("list", help="the tables, their files and generator functions")
    a = sub.add_parser("all", help="every table from scratch, in order: "
                       + ", ".join(TABLES) + " (the capillary tables at their full stage)")
    a.add_argument("--workers", type=int, default=2,
                   help="processes solving the meniscus nodes of the capillary tables "
                        "(default 2)")
    v = sub.add_parser("calibrated-viscous", help=TABLES["calibrated-viscous"][2])
    v.add_argument("--workers", type=int, default=None, help="not used (one process)")
    c = sub.add_parser("calibrated-capillary", help=TABLES["calibrated-capillary"][2])
    c.add_argument("--kind", choices=[*CAPILLARY_KINDS, "all"], default="all",
                   help="one table (two contact angles: sphere-wall-two-angles, "
                        "sphere-sphere-two-angles); the others are kept as they are; 'all' "
                        "is the first three")
    c.add_argument("--workers", type=int, default=2,
                   help="processes solving the meniscus nodes (default 2)")
    c.add_argument("--held-out", type=int, default=120, help="held-out bridges per kind")
    c.add_argument("--stage", choices=["coarse", "medium", "full"], default="full",
                   help="sphere-sphere-two-angles only: the node counts (nested: each "
                        "stage reuses what the ones before it solved; full is shipped)")
    c.add_argument("--out", type=Path, default=None,
                   help="write into this copy of the table file, made from the package "
                        "data's if it does not exist (default: the package data itself)")
    c.add_argument("--retrain", action="store_true",
                   help="keep the fit the file holds, build its tensor trains again (the "
                        "two-angle tables) and measure its held-out tables again (no node "
                        "solved; --stage is ignored)")
    c.add_argument("--corners", action="store_true",
                   help="measure only the corner stratum (held_out_corners: the domain's "
                        "ends and middles at gaps up to 0.999 S_c) of every table the package "
                        "data holds, or of --kind's, against meniscus; nothing is refitted")
    c.add_argument("--refine-band", type=int, nargs="+", default=None, metavar="BAND",
                   help="the two-angle tables only (--kind): fit again the pieces of these "
                        "bands (0-2) whose node counts differ from the generator's, from "
                        "each band's own ridge series (searched again only at the w nodes a "
                        "pair band's ridge gains), and measure the table's held-out tables "
                        "again, once")
    for sp in (a, c):
        sp.add_argument("--dask", action="store_true",
                        help="solve the meniscus nodes on a local Dask cluster of --workers "
                             "processes (the sweep's machinery) instead of a process pool")
        sp.add_argument("--scheduler", default=None, metavar="ADDR",
                        help="solve the meniscus nodes on the Dask cluster at ADDR "
                             "(tcp://HOST:PORT; workers started with `dask worker ADDR`, "
                             "the same code installed)")
    t = sub.add_parser("transfer-fraction", help=TABLES["transfer-fraction"][2])
    t.add_argument("--held-out", type=int, default=200, help="held-out points (default 200)")
    t.add_argument("--workers", type=int, default=2, help="processes for the meniscus solves "
                   "(default 2)")
    d = sub.add_parser("dynamic-rupture", help=TABLES["dynamic-rupture"][2])
    d.add_argument("--workers", type=int, default=2, help="processes for the stretching runs "
                   "(default 2)")
    b = sub.add_parser("bounds", help=TABLES["bounds"][2])
    b.add_argument("--quick", action="store_true",
                   help="fewer held-out scenes per table (a smoke run; the shipped tables "
                        "are not --quick)")
    b.add_argument("--seed", type=int, default=20261123,
                   help="seed of the held-out scenes (default: the shipped tables' seed)")
    b.add_argument("--out", type=Path, default=None,
                   help="JSON file to write (default: the package data; with --quick: "
                        "bounds-quick.json in the current folder, so that a smoke run never "
                        "replaces the shipped tables)")
    b.add_argument("--closure", choices=list(ALONE), default=None,
                   help="measure only this closure's tables again, in place in the file a "
                        "whole run wrote (same --seed and --quick): what a change of the "
                        "closure itself calls for")
    b.add_argument("--workers", type=int, default=None, help="not used (one process)")
    f = sub.add_parser("fit", help="refit closure families on their default designs (files "
                       "of your own, not package data)")
    f.add_argument("family", choices=sorted(FAMILIES) + ["all"])
    f.add_argument("--out", type=Path, required=True, help="JSON file (a folder for 'all')")
    f.add_argument("--train", type=int, default=30,
                   help="about this many training configurations, a full grid over the "
                        "family's design (8 gaps each; default 30)")
    f.add_argument("--held-out", type=int, default=16,
                   help="seeded random held-out configurations (6 gaps each; default 16)")
    f.add_argument("--reuse", action="store_true", help="refit from the saved points")
    return p


def _viscous() -> None:
    from wetcontact.generate.calibrated_viscous import generate_calibrated_viscous

    data = generate_calibrated_viscous()
    for k, v in data["immersed"].items():
        print(f"immersed {k}: held-out max {v['held_out']['max']:.3g}")
    for label, d in (("film", data["film"]), *(
            (f"bridge {k}", v) for k, v in data["bridge"].items())):
        ho = d["held_out"]
        print(f"{label}: held-out max {ho['before']['max']:.3g} (Pitois) -> "
              f"{ho['after']['max']:.3g}")
    print(f"{data['wall_time_s']} s")


def _check_capillary(p: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse ``--refine-band`` outside the two-angle tables or with other bands than 0-2."""
    if args.refine_band is None:
        return
    if args.kind not in (cc.WALL_TWO_ANGLES, PAIR_KIND):
        p.error(f"--refine-band: only with --kind {cc.WALL_TWO_ANGLES} or --kind "
                f"{PAIR_KIND} (given: --kind {args.kind})")
    bad = [b for b in args.refine_band if b not in (0, 1, 2)]
    if bad or len(set(args.refine_band)) < len(args.refine_band):
        p.error(f"--refine-band = {' '.join(map(str, args.refine_band))}; allowed: "
                "distinct bands 0, 1 or 2")


def _capillary(args: argparse.Namespace) -> None:
    if args.refine_band is not None:
        from wetcontact.generate.calibrated_capillary_pairs import refine_band

        entry = refine_band(args.kind, args.refine_band, _table_copy(args.out), args.workers)
        _print_held_out(args.kind, entry)
        for b in args.refine_band:
            rec = entry["refine_band"][str(b)]
            print(f"band {b}: {rec['wall_time_s']} s "
                  f"(held-out tables {rec['held_out_wall_time_s']} s)")
        return
    if args.corners:
        from wetcontact.generate.calibrated_capillary import CORNER_KINDS, add_corner_strata

        kinds = CORNER_KINDS if args.kind == "all" else (args.kind,)
        data = add_corner_strata(_table_copy(args.out), kinds, args.workers)
        for kind in kinds:
            if kind in data:
                ho = data[kind]["held_out_corners"]
                print(f"{kind} held_out_corners: max rupture "
                      f"{ho['rupture_distance']['max']:.3g}, force {ho['force']['max']:.3g} "
                      f"({ho['force']['points']} points, {ho['bridges']} bridges)")
        return
    if args.kind == PAIR_KIND:
        from wetcontact.generate.calibrated_capillary_pairs import generate_pair_table

        entry = generate_pair_table(args.stage, _table_copy(args.out), args.workers,
                                    args.held_out, retrain=args.retrain)
        _print_held_out(args.kind, entry)
        print(f"{entry['retrain_wall_time_s' if args.retrain else 'wall_time_s']} s")
        return
    from wetcontact.generate.calibrated_capillary import KINDS, generate_calibrated_capillary

    kinds = KINDS if args.kind == "all" else (args.kind,)
    data = generate_calibrated_capillary(_table_copy(args.out), kinds=kinds,
                                         workers=args.workers, n_held_out=args.held_out,
                                         retrain=args.retrain)
    for kind in kinds:
        ho = data[kind]["held_out"]
        print(f"{kind}: held-out max rupture {ho['rupture_distance']['max']:.3g}, "
              f"force {ho['force']['max']:.3g} ({ho['force']['points']} points)")
    print(f"{data['retrain_wall_time_s' if args.retrain else 'wall_time_s']} s")


def _bounds(args: argparse.Namespace) -> None:
    from wetcontact.generate.bounds import measure_bounds

    out = args.out or (Path("bounds-quick.json") if args.quick else DATA_PATH)
    data = measure_bounds(seed=args.seed, out=out, quick=args.quick, progress=True,
                          closure=args.closure)
    if args.closure:
        done = data["remeasured"][args.closure]
        print(f"wrote {out} ({done['tables']} {args.closure} tables measured again, "
              f"{done['wall_time_s']} s)")
    else:
        print(f"wrote {out} ({len(data['tables'])} tables, {data['wall_time_s']} s)")


def _fit(args: argparse.Namespace) -> None:
    names = sorted(FAMILIES) if args.family == "all" else [args.family]
    for name in names:
        out = args.out / f"{name}.json" if args.family == "all" else args.out
        cal = run_family(name, out, args.train, args.held_out, reuse=args.reuse)
        ho = cal.held_out
        print(f"{cal.family}: held-out max {ho['before']['max']:.3g} -> "
              f"{ho['after']['max']:.3g} (goal 1/3: "
              f"{'met' if cal.goal_met else 'NOT met'}); wrote {out}", flush=True)


def main(argv: list[str] | None = None) -> int:
    """Run one table's generator, all of them, ``list`` or ``fit``; returns the exit code."""
    p = parser()
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    if args.command == "list":
        for name, (file, func, what) in TABLES.items():
            print(f"{name:<22} {file:<26} {what}\n{'':<22} {func}")
        return 0
    if args.command == "fit":
        _fit(args)
        return 0
    if args.command in ("calibrated-viscous", "all"):
        _say("calibrated-viscous")
        _workers_unused("calibrated-viscous", None if args.command == "all" else args.workers)
        _viscous()
    if args.command == "all":
        _say("calibrated-capillary")
        with open_workers(args.workers, args.scheduler, args.dask) as workers:
            for kind in ("all", PAIR_KIND):  # 'all': the first three kinds; then the pairs
                _capillary(argparse.Namespace(kind=kind, workers=workers, held_out=120,
                                              stage="full", out=None, retrain=False,
                                              corners=False, refine_band=None))
    elif args.command == "calibrated-capillary":
        _check_capillary(p, args)
        _say("calibrated-capillary", args.out)
        with open_workers(args.workers, args.scheduler, args.dask) as workers:
            _capillary(argparse.Namespace(**{**vars(args), "workers": workers}))
    if args.command in ("transfer-fraction", "all"):
        from wetcontact.generate.transfer_fraction import generate_transfer_fraction

        _say("transfer-fraction")
        n = args.held_out if args.command == "transfer-fraction" else 200
        rec = generate_transfer_fraction(n_held_out=n, workers=max(1, args.workers))
        print(f"{rec['build_wall_time_this_run_s']} s build, {rec['solves_this_run']} solves "
              f"(of {rec['solve_calls']})")
    if args.command in ("dynamic-rupture", "all"):
        from wetcontact.generate.dynamic_rupture import generate_dynamic_rupture

        _say("dynamic-rupture")
        data = generate_dynamic_rupture(workers=max(1, args.workers))
        print(f"{data['wall_time_s']} s")
    if args.command in ("bounds", "all"):
        if args.command == "bounds":
            _say("bounds", args.out or (Path("bounds-quick.json") if args.quick else None))
            _workers_unused("bounds", args.workers)
        else:
            _say("bounds")
            args = argparse.Namespace(quick=False, seed=20261123, out=None, closure=None)
        _bounds(args)
    if args.command == "all":
        print(f"generate all: {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except InputError as exc:  # bad input: one line, exit 2, no traceback
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        sys.exit(2)
