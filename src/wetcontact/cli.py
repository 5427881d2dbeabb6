"""The ``wetcontact`` command.

Exit codes: 0 success, 2 bad input (one line on stderr, no traceback), 1 solver failure.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from wetcontact.errors import InputError, SolverError


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message} (see --help)\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="wetcontact", description="High-fidelity reference forces for wet "
                "particle contacts, and the error tables of DEM force closures.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    run = sub.add_parser("run", help="regenerate reference curves, error tables and the "
                         "report into reports/", description="The main job: every case in "
                         "cases/ with every applicable model, the store, plots, error tables "
                         "and reports/README.md.")
    mode = run.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="smoke run: fast presets, fewer "
                      "points (about a minute)")
    mode.add_argument("--full", action="store_true", help="accurate presets and full studies")
    run.add_argument("--out", type=Path, default=Path("reports"), help="output folder "
                     "(default: reports/)")
    run.add_argument("--cases", type=Path, default=Path("cases"), help="case folder "
                     "(default: cases/)")
    run.add_argument("--resume", action="store_true", help="reuse curves already in the store")

    solve = sub.add_parser("solve", help="solve one case file", description="Solve one case "
                           "with a named model, or with the cheapest model meeting a tolerance.")
    solve.add_argument("case", type=Path, help="TOML case file")
    solve.add_argument("--model", help="model name (see `wetcontact models`)")
    solve.add_argument("--preset", choices=("fast", "default", "accurate"), default=None,
                       help="resolution preset (default: default)")
    solve.add_argument("--tol", type=float, help="relative tolerance: pick the cheapest model "
                       "that meets it")
    solve.add_argument("--json", action="store_true", help="print one JSON object")
    solve.add_argument("--save-fields", type=Path, default=None, metavar="DIR",
                       help="write solution fields (VTU) where the model supports it")

    _add_sweep_parser(sub)
    _add_export_parser(sub)
    sub.add_parser("models", help="list the registered models", description="Registered "
                   "models with their fidelity level, component and validity range.")
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``wetcontact`` command."""
    args = build_parser().parse_args(argv)
    try:
        if args.command == "models":
            return _models()
        if args.command == "solve":
            return _solve(args)
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "export":
            return _export(args)
        if args.command == "run":
            from wetcontact.report import run_all

            run_all(cases=args.cases, out=args.out,
                    mode="quick" if args.quick else "full" if args.full else "default",
                    resume=args.resume)
            return 0
    except InputError as exc:
        sys.stderr.write(f"wetcontact: error: {exc}\n")
        return 2
    except SolverError as exc:
        sys.stderr.write(f"wetcontact: solver failed: {exc}\n")
        return 1
    except KeyboardInterrupt:
        sys.stderr.write("wetcontact: interrupted; everything saved before is in the store\n")
        return 130
    return 2


def _models() -> int:
    from wetcontact.models import load_all

    rows = [(m.name, str(m.level), m.component, m.validity)
            for m in sorted(load_all().values(), key=lambda m: (m.level, m.name))]
    w = [max(len(r[i]) for r in rows + [("model", "level", "component", "")]) for i in range(3)]
    print(f"{'model':<{w[0]}}  {'level':<{w[1]}}  {'component':<{w[2]}}  validity")
    for r in rows:
        print(f"{r[0]:<{w[0]}}  {r[1]:<{w[1]}}  {r[2]:<{w[2]}}  {r[3]}")
    return 0


def _solve(args: argparse.Namespace) -> int:
    from wetcontact.models import get_model
    from wetcontact.scene import load_case
    from wetcontact.select import choose_model

    scene = load_case(args.case)
    if args.model and args.tol is not None:
        raise InputError("--model and --tol: give one, not both")
    name = args.model or (scene.model if args.tol is None else None)
    if name:
        model, preset, why = get_model(name), args.preset or "default", "requested"
    else:
        tol = args.tol if args.tol is not None else scene.tolerance
        if tol is None:
            raise InputError(f"{args.case}: no model: give --model, --tol, or fidelity.model / "
                             "fidelity.tolerance in the case file")
        choice = choose_model(scene, tol)
        model, preset, why = choice.model, args.preset or choice.preset, choice.reason
    opts = {}
    if args.save_fields is not None:
        if not model.saves_fields:
            raise InputError(f"--save-fields: model '{model.name}' has no fields to save; "
                             "use a field solver (stokes)")
        opts["save_fields"] = str(args.save_fields)
    curve = model.force(scene, preset=preset, **opts)
    if args.json:
        out = curve.to_json_dict()
        out["selection"] = why
        print(json.dumps(out))
    else:
        print(f"# case {scene.name}  model {model.name} ({why}), preset {preset}, "
              f"{curve.diagnostics.get('wall_time_s', 0):.3g} s")
        cols = [("gap_m", curve.gap), ("F_viscous_N", curve.force_viscous),
                ("F_capillary_N", curve.force_capillary), ("F_total_N", curve.force_total)]
        cols = [(n, c) for n, c in cols if c is not None]
        print("  ".join(f"{n:>14}" for n, _ in cols))
        for i in range(curve.gap.size):
            print("  ".join(f"{c[i]:>14.6e}" for _, c in cols))
    return 0


def _add_sweep_parser(sub: argparse._SubParsersAction) -> None:
    sw = sub.add_parser("sweep", help="solve a study's points into the store (Dask)",
                        description="Solve every (scene, model) point of a study file into "
                        "the HDF5 store on a local Dask cluster (default) or an existing one; "
                        "points already stored are reused, failures are recorded.")
    sw.add_argument("study", type=Path, help="TOML study file (cases/studies/)")
    where = sw.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_non_negative_int, default=None, metavar="N",
                       help="local worker processes (default: one per core; 0 = in this "
                       "process; small sweeps run in this process by default)")
    where.add_argument("--scheduler", metavar="ADDRESS", help="tcp://HOST:PORT of a running "
                       "Dask scheduler (dask scheduler / dask worker, dask-jobqueue)")
    sw.add_argument("--store", type=Path, default=Path("reference.h5"),
                    help="HDF5 store (default: ./reference.h5)")
    sw.add_argument("--wait", type=float, default=0.0, metavar="SECONDS",
                    help="wait this long for another writer of the store (default: 0, "
                    "exit 2 at once)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="solve again the points whose failure is recorded in the store")
    sw.add_argument("--json", action="store_true", help="end with one JSON object: study, "
                    "points, computed, reused, failed, store, wall_time_s")


def _add_export_parser(sub: argparse._SubParsersAction) -> None:
    ex = sub.add_parser("export", help="write stored curves for other tools",
                        description="Export stored reference curves.")
    fmt = ex.add_subparsers(dest="format", required=True, parser_class=_Parser)
    c = fmt.add_parser("csv", help="one row per (point, model, gap)", description="One CSV "
                       "row per (point, model, gap) of a study, a column per axis.")
    c.add_argument("study", type=Path, help="TOML study file")
    c.add_argument("--store", type=Path, required=True, help="HDF5 store the sweep wrote")
    c.add_argument("--out", type=Path, required=True, help="CSV file to write")


def _non_negative_int(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = -1
    if n < 0:
        raise argparse.ArgumentTypeError(f"--workers = {text!r}; allowed: an integer >= 0")
    return n


def _sweep(args: argparse.Namespace) -> int:
    from wetcontact.store import Store
    from wetcontact.study import load_study
    from wetcontact.sweep import sweep

    study = load_study(args.study)
    if args.wait < 0 or args.wait != args.wait:
        raise InputError(f"--wait = {args.wait!r}; allowed: seconds >= 0")
    res = sweep(study.points(), Store(args.store), workers=args.workers,
                scheduler=args.scheduler, progress=True, retry_failed=args.retry_failed,
                lock_timeout=args.wait, keep_curves=False)
    summary = res.summary(study.name)
    if args.json:
        print(json.dumps(summary))
        return 0
    print(f"study {study.name}: {summary['points']} points, {summary['computed']} computed, "
          f"{summary['reused']} reused, {summary['failed']} failed in "
          f"{summary['wall_time_s']:.3g} s ({res.executor}) -> {res.store}")
    reasons: dict[str, int] = {}
    for o in res.outcomes:
        if o.status == "failed":
            reasons[f"{o.point.model}: {o.reason}"] = reasons.get(
                f"{o.point.model}: {o.reason}", 0) + 1
    for why, n in sorted(reasons.items(), key=lambda kv: -kv[1])[:5]:
        print(f"  failed x{n}: {why}")
    return 0


def _export(args: argparse.Namespace) -> int:
    if args.format == "csv":
        from wetcontact.export.csv import write_csv
        from wetcontact.store import Store
        from wetcontact.study import load_study

        if not args.store.is_file():
            raise InputError(f"--store {args.store}: no such store; run `wetcontact sweep` "
                             "first")
        if not args.out.parent.is_dir():
            raise InputError(f"--out {args.out}: the folder {args.out.parent} does not exist")
        study = load_study(args.study)
        counts = write_csv(study.points(), study.axes, Store(args.store), args.out)
        print(f"{args.out}: {counts['rows']} rows ({counts['ok']} ok, {counts['no-bridge']} "
              f"no-bridge, {counts['failed']} failed, {counts['missing']} missing)")
        return 0
    return 2


if __name__ == "__main__":
    raise SystemExit(main())
