"""The ``wetcontact`` command's argument parser: every sub-command and flag.

Flags are checked here as far as argparse can (a path is not empty, ``--workers`` is an
integer >= 0, an ``--out`` ending in a separator names an existing folder); a bad flag is
one line on stderr and exit code 2. The commands themselves run in :mod:`wetcontact.cli`.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from wetcontact import __version__
from wetcontact.errors import short_repr


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {short_repr(message, quote=False, limit=300)} "
                         "(see --help)\n")
        raise SystemExit(2)


def path_arg(text: str) -> Path:
    """A path flag's value: any non-empty path (an empty one would mean the current folder
    or raise deep inside a writer)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; give a file or folder name")
    return Path(text)


def file_out_arg(text: str) -> Path:
    """An ``--out`` that is a file, or an existing folder to write the default name in: a
    path ending in a separator names a folder, so it must exist (``Path`` would drop the
    separator and write a file of that name)."""
    path = path_arg(text)
    if text.endswith(("/", os.sep)) and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} names a folder that does not exist; "
                                         "create it first, or give a file name")
    return path


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="wetcontact", description="High-fidelity reference forces for wet "
                "particle contacts, and the error tables of DEM force closures.")
    p.add_argument("--version", action="version", version=f"wetcontact {__version__}")
    p.add_argument("--debug", action="store_true", help="show the traceback of a failure "
                   "(or set WETCONTACT_DEBUG=1)")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    run = sub.add_parser("run", help="regenerate reference curves, error tables and the "
                         "report into reports/", description="The main job: every case in "
                         "cases/ with every applicable model, the store, plots, error tables "
                         "and reports/README.md.")
    mode = run.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="smoke run: fast presets, at most 8 "
                      "gaps a case, smaller studies (about 75 s on 2 cores)")
    mode.add_argument("--full", action="store_true", help="accurate presets and full studies")
    run.add_argument("--out", type=path_arg, default=None, help="output folder (default: "
                     "reports/; with --quick: reports-quick/, so a smoke run never "
                     "overwrites the committed report)")
    run.add_argument("--cases", type=path_arg, default=Path("cases"), help="case folder "
                     "(default: cases/)")
    run.add_argument("--resume", action="store_true", help="reuse curves already in the store")
    run.add_argument("--bench", type=path_arg, default=Path("benchmarks/results/thinfilm.json"),
                     help="thin-film benchmark JSON for the stability map and the wetting-"
                     "width study (default: benchmarks/results/thinfilm.json; the section "
                     "says so when it is absent)")

    solve = sub.add_parser("solve", help="solve one case file", description="Solve one case "
                           "with a named model, or with the cheapest model meeting a tolerance.")
    solve.add_argument("case", type=path_arg, help="TOML case file")
    solve.add_argument("--model", help="model name (see `wetcontact models`)")
    solve.add_argument("--preset", choices=("fast", "default", "accurate"), default=None,
                       help="resolution preset (default: default)")
    solve.add_argument("--tol", type=float, help="relative tolerance: pick, per force "
                       "component, the cheapest model whose measured bound meets it")
    solve.add_argument("--coefficients", type=path_arg, default=None, metavar="FILE.json",
                       help="refitted coefficients of the closure family given by --model "
                       "(from calibration); outside their domain the model refuses")
    solve.add_argument("--json", action="store_true", help="print one JSON object")
    solve.add_argument("--save-fields", type=path_arg, default=None, metavar="DIR",
                       help="write solution fields (VTU, and a ParaView .pvd listing them by "
                       "gap) where the model supports it")

    _add_compare_parser(sub)
    _add_calibrate_parser(sub)
    from wetcontact.collide.command import add_parser as add_collide_parser

    add_collide_parser(sub, path_arg)
    _add_sweep_parser(sub)
    _add_export_parser(sub)

    m = sub.add_parser("models", help="list the registered models", description="Registered "
                       "models with their fidelity level, component, validity range and "
                       "source paper.")
    m.add_argument("--json", action="store_true", help="print one JSON object: model name -> "
                   "level, component, validity, source, order")
    return p


def _add_compare_parser(sub: argparse._SubParsersAction) -> None:
    """``wetcontact compare CASE``: the closure error table and figure of one case."""
    c = sub.add_parser("compare", help="closure error table (CSV) and figure (PNG) of one "
                       "case", description="Every model that applies to the case (or the "
                       "named ones) against the case's reference, as in the report of "
                       "`wetcontact run` but for this case alone, without the studies. "
                       "Writes closure_errors.csv, curves/CASE.png and curves/CASE.csv, and "
                       "the curves into reference.h5 (a rerun reuses them).")
    c.add_argument("case", type=path_arg, help="TOML case file")
    c.add_argument("--models", default=None, metavar="A,B,...", help="models to compare, "
                   "comma-separated, at any level (default: every closure that applies); "
                   "one that does not apply is listed with its reason")
    c.add_argument("--out", type=path_arg, default=None, metavar="DIR",
                   help="output folder (default: compare-CASE/)")
    c.add_argument("--preset", choices=("fast", "default", "accurate"), default="default",
                   help="resolution preset of the solvers (default: default)")
    c.add_argument("--workers", type=_non_negative_int, default=None, metavar="N",
                   help="local worker processes (default: one per core for long sweeps; "
                   "0 = in this process)")
    c.add_argument("--json", action="store_true", help="print one JSON object: case, "
                   "references, rows, not_applicable, failed, files, counts")


def _add_calibrate_parser(sub: argparse._SubParsersAction) -> None:
    c = sub.add_parser("calibrate", help="refit a closure family to a study's references",
                       description="Fit a closure family's coefficients to the reference "
                       "points of a study (its model of highest reference rank for the "
                       "family's force component; swept into the store first when "
                       "missing), train on the study's grid and report on a seeded held-out "
                       "design the fit never saw. Writes the JSON, a parity plot and an "
                       "error map beside it.")
    c.add_argument("study", type=path_arg, help="TOML study file (cases/studies/calibrate-*.toml)")
    c.add_argument("--closure", required=True, metavar="FAMILY",
                   help="closure family (an unknown name lists the families)")
    c.add_argument("--out", type=path_arg, required=True, metavar="FILE.json",
                   help="calibration JSON (PNG plots and the held-out study beside it)")
    c.add_argument("--store", type=path_arg, default=Path("reference.h5"),
                   help="HDF5 store of the reference points (default: ./reference.h5)")
    c.add_argument("--workers", type=_non_negative_int, default=None, metavar="N",
                   help="local Dask workers for the missing points (default: one per core; "
                   "0 = in this process)")
    held = c.add_mutually_exclusive_group()
    held.add_argument("--held-out", type=path_arg, default=None, metavar="STUDY2.toml",
                      help="held-out study file (default: a Latin hypercube over the study's "
                      "ranges)")
    held.add_argument("--held-out-points", type=int, default=120, metavar="N",
                      help="points of the seeded held-out Latin hypercube (default: 120)")
    c.add_argument("--seed", type=int, default=7919, help="seed of the held-out design "
                   "(default: 7919)")


def _add_sweep_parser(sub: argparse._SubParsersAction) -> None:
    sw = sub.add_parser("sweep", help="solve a study's points into the store (Dask)",
                        description="Solve every (scene, model) point of a study file into "
                        "the HDF5 store on a local Dask cluster (default) or an existing one; "
                        "points already stored are reused, failures are recorded.")
    sw.add_argument("study", type=path_arg, help="TOML study file (cases/studies/)")
    where = sw.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_non_negative_int, default=None, metavar="N",
                       help="local worker processes (default: one per core; 0 = in this "
                       "process; small sweeps run in this process by default)")
    where.add_argument("--scheduler", metavar="ADDRESS", help="tcp://HOST:PORT of a running "
                       "Dask scheduler (dask scheduler / dask worker, dask-jobqueue)")
    sw.add_argument("--store", type=path_arg, default=Path("reference.h5"),
                    help="HDF5 store (default: ./reference.h5)")
    sw.add_argument("--wait", type=float, default=0.0, metavar="SECONDS",
                    help="wait this long for another writer of the store (default: 0, "
                    "exit 2 at once)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="solve again the points whose failure is recorded in the store")
    sw.add_argument("--json", action="store_true", help="end with one JSON object: study, "
                    "points, computed, reused, failed, store, wall_time_s")


def _add_export_parser(sub: argparse._SubParsersAction) -> None:
    ex = sub.add_parser("export", help="write calibrated closures for DEM codes (json, "
                        "python, c), Yade capillary tables, or stored curves (csv)",
                        description="Export stored reference curves (csv), "
                        "calibrated closures (json, python, c) and Yade's capillary tables "
                        "(yade).")
    fmt = ex.add_subparsers(dest="format", required=True, parser_class=_Parser)
    c = fmt.add_parser("csv", help="one row per (point, model, gap)", description="One CSV "
                       "row per (point, model, gap) of a study, a column per axis.")
    c.add_argument("study", type=path_arg, help="TOML study file")
    c.add_argument("--store", type=path_arg, required=True, help="HDF5 store the sweep wrote")
    c.add_argument("--out", type=path_arg, required=True, help="CSV file to write")
    c.add_argument("--json", action="store_true", help="print one JSON object")
    _add_export_yade(fmt)
    yl = fmt.add_parser("yade-liquid", help="Yade's liquid-migration terms Vf1, Vf2 from "
                        "the calibrated division at rupture",
                        description="A module for Yade scripts: apply_liquid_division(O) "
                        "sets Vf1 = f Vb and Vf2 = (1 - f) Vb on every active bridge, f the "
                        "calibrated transfer fraction (needs a Yade built with "
                        "YADE_LIQMIGRATION).")
    yl.add_argument("--out", type=file_out_arg, required=True,
                    help="file to write (or an existing folder: wetcontact_liquid.py in it)")
    yl.add_argument("--json", action="store_true", help="print one JSON object")
    _add_export_closure_parsers(fmt)


def _add_export_yade(fmt: argparse._SubParsersAction) -> None:
    """``wetcontact export yade``: Yade's ten capillary files for one contact angle."""
    y = fmt.add_parser("yade", help="Yade's capillary files M(r=1) ... M(r=10)",
                       description="The ten capillary files that Yade's "
                       "Law2_ScGeom_CapillaryPhys_Capillarity reads, for any contact angle; "
                       "pass the printed suffix to Yade as suffCapFiles.")
    y.add_argument("--contact-angle", type=float, required=True, metavar="DEG",
                   help="contact angle on both spheres (deg, [0, 89))")
    y.add_argument("--out", type=path_arg, required=True, help="output folder")
    y.add_argument("--suffix", default=None, help="file name suffix (default: _thetaDEG)")
    y.add_argument("--suctions", type=int, default=350, help="suction values per file "
                   "(default 350, Yade's usual)")
    y.add_argument("--distances", type=int, default=80, help="distance values per file "
                   "(default 80, Yade's usual)")
    y.add_argument("--workers", type=_non_negative_int, default=2, metavar="N",
                   help="processes (default 2; 0 or 1 = in this process)")
    y.add_argument("--json", action="store_true", help="end with one JSON object")


def _add_export_closure_parsers(fmt: argparse._SubParsersAction) -> None:
    """``export json|python|c``: calibrated closures in the forms DEM codes take."""
    j = fmt.add_parser("json", help="a shipped or refitted calibration as one JSON",
                       description="Coefficients, domain, held-out errors, units, sign "
                       "convention and provenance, validated against the package's schema.")
    src = j.add_mutually_exclusive_group(required=True)
    src.add_argument("--closure", help="a shipped calibrated closure (calibrated-viscous or "
                     "calibrated-capillary)")
    src.add_argument("--coefficients", type=path_arg, metavar="FILE.json",
                     help="a refit written by `python -m wetcontact.generate fit`")
    j.add_argument("--out", type=file_out_arg, required=True, help="JSON file to write")
    j.add_argument("--json", action="store_true", help="print one JSON object")
    for name, what, default in (
            ("python", "one numpy-only module with the calibrated closures",
             "wetcontact_closures.py"),
            ("c", "one header-only C99 file with the calibrated closures",
             "wetcontact_closures.h")):
        q = fmt.add_parser(name, help=what, description=what[0].upper() + what[1:]
                           + ": the shipped calibrated-viscous (immersed and bridge) and "
                           "calibrated-capillary "
                           "(one contact angle on both solids, or one on each), and the "
                           "REFITTED willett force and lian-rupture distance as *_refit "
                           "(two contact angles).")
        q.add_argument("--out", type=file_out_arg, required=True,
                       help=f"file to write (or an existing folder: {default} in it)")
        q.add_argument("--capillary", type=path_arg, default=None, metavar="FILE.json",
                       help="willett refit for capillary_force_refit (default: the "
                       "package's copy of benchmarks/results/calibration/willett.json)")
        q.add_argument("--rupture", type=path_arg, default=None, metavar="FILE.json",
                       help="lian-rupture refit for rupture_distance_refit (default: the "
                       "package's copy of benchmarks/results/calibration/lian-rupture.json)")
        q.add_argument("--refit", type=path_arg, action="append", default=[],
                       metavar="FILE.json", help="a refit of any family (written by "
                       "`wetcontact calibrate` or `python -m wetcontact.generate fit`), "
                       "exported as one more function named after its family, "
                       "refit_<family> (C: wc_refit_<family>, '-' as '_'); repeatable, one "
                       "file per family")
        q.add_argument("--json", action="store_true", help="print one JSON object")


def _non_negative_int(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = -1
    if n < 0:
        raise argparse.ArgumentTypeError(f"--workers = {text!r}; allowed: an integer >= 0")
    return n
