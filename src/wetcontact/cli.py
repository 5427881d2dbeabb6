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

    _add_export_yade(sub)

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
        if args.command == "export" and args.format == "yade":
            return _export_yade(args)
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


def _add_export_yade(sub) -> None:
    """``wetcontact export yade``: Yade's ten capillary files for one contact angle."""
    export = sub.add_parser("export", help="write results in a DEM code's format",
                            description="Export for DEM codes.")
    fmt = export.add_subparsers(dest="format", required=True, parser_class=_Parser)
    y = fmt.add_parser("yade", help="Yade's capillary files M(r=1) ... M(r=10)",
                       description="The ten capillary files that Yade's "
                       "Law2_ScGeom_CapillaryPhys_Capillarity reads, for any contact angle; "
                       "pass the printed suffix to Yade as suffCapFiles.")
    y.add_argument("--contact-angle", type=float, required=True, metavar="DEG",
                   help="contact angle on both spheres (deg, [0, 89))")
    y.add_argument("--out", type=Path, required=True, help="output folder")
    y.add_argument("--suffix", default=None, help="file name suffix (default: _thetaDEG)")
    y.add_argument("--suctions", type=int, default=350, help="suction values per file "
                   "(default 350, Yade's usual)")
    y.add_argument("--distances", type=int, default=80, help="distance values per file "
                   "(default 80, Yade's usual)")
    y.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    y.add_argument("--json", action="store_true", help="end with one JSON object")


def _export_yade(args: argparse.Namespace) -> int:
    from wetcontact.export.yade import export_yade

    res = export_yade(args.contact_angle, args.out, n_suctions=args.suctions,
                      n_distances=args.distances, workers=args.workers, suffix=args.suffix)
    if args.json:
        print(json.dumps(res))
    else:
        for t in res["tables"]:
            print(f"{t['file']}: {t['rows']} rows, {t['wall_time_s']:.1f} s")
        print(f"suffCapFiles = {res['suffix']!r}  ({res['wall_time_s']:.1f} s)")
    return 0


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


if __name__ == "__main__":
    raise SystemExit(main())
