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
    solve.add_argument("--tol", type=float, help="relative tolerance: pick, per force "
                       "component, the cheapest model whose measured bound meets it")
    solve.add_argument("--coefficients", type=Path, default=None, metavar="FILE.json",
                       help="refitted coefficients of the closure family given by --model "
                       "(from calibration); outside their domain the model refuses")
    solve.add_argument("--json", action="store_true", help="print one JSON object")
    solve.add_argument("--save-fields", type=Path, default=None, metavar="DIR",
                       help="write solution fields (VTU) where the model supports it")

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
    from wetcontact import select
    from wetcontact.models import get_model
    from wetcontact.scene import load_case

    scene = load_case(args.case)
    if args.model and args.tol is not None:
        raise InputError("--model and --tol: give one, not both")
    coefficients = getattr(args, "coefficients", None)
    if coefficients is not None and not args.model:
        raise InputError("--coefficients needs --model FAMILY (the closure family they fit)")
    name = args.model or (scene.model if args.tol is None else None)
    names: dict[str, str | None] = {}
    if name:
        preset, why = args.preset or "default", "requested"
        opts = {}
        if coefficients is not None:
            from wetcontact.calibrate import load_coefficients

            model = load_coefficients(coefficients, family=name)
            why = f"coefficients from {coefficients}"
        else:
            model = get_model(name)
        if args.save_fields is not None:
            if not model.saves_fields:
                raise InputError(f"--save-fields: model '{model.name}' has no fields to "
                                 "save; use a field solver (stokes)")
            opts["save_fields"] = str(args.save_fields)
        curve = model.force(scene, preset=preset, **opts)
        for comp, arr in (("viscous", curve.force_viscous),
                          ("capillary", curve.force_capillary)):
            names[comp] = model.name if arr is not None else None
    else:
        tol = args.tol if args.tol is not None else scene.tolerance
        if tol is None:
            raise InputError(f"{args.case}: no model: give --model, --tol, or fidelity.model / "
                             "fidelity.tolerance in the case file")
        if args.save_fields is not None:
            raise InputError("--save-fields needs --model (a field solver, e.g. stokes)")
        curve, sel = select.solve(scene, tol, preset=args.preset)
        preset, why = args.preset or "per component", sel.reason
        names = {c: (sel.choices[c].model.name if c in sel.choices else None)
                 for c in select.COMPONENTS}
        for ch in sel.choices.values():
            if not ch.met:
                sys.stderr.write(f"wetcontact: warning: {ch.component} force: {ch.reason}\n")
    if args.json:
        out = curve.to_json_dict()
        out["model_viscous"] = names.get("viscous")
        out["model_capillary"] = names.get("capillary")
        out["selection"] = why
        print(json.dumps(out))
    else:
        print(f"# case {scene.name}  model {curve.model} ({why}), preset {preset}, "
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
