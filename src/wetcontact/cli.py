"""The ``wetcontact`` command.

Exit codes: 0 success, 2 bad input or a path the user must change (one line on stderr, no
traceback), 1 a solver failure or an unexpected error (one line; ``--debug`` or
``WETCONTACT_DEBUG=1`` shows the traceback), 130 interrupted, 143 terminated (SIGTERM).
The parser (every sub-command and flag) is :mod:`wetcontact.cli_parser`.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import json
import math
import os
import signal
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from wetcontact.cli_parser import build_parser, file_out_arg, path_arg  # noqa: F401 (public here too)
from wetcontact.errors import InputError, SolverError
from wetcontact.fileio import writable_file
from wetcontact.progress import Ticker

if TYPE_CHECKING:  # the CLI imports its subcommands' modules only when they run
    from wetcontact.models import ForceCurve
    from wetcontact.study import Study


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``wetcontact`` command: the one error boundary.

    Every failure leaves as exit 2 (bad input, a user's path) or 1 (a solver failure, an
    unexpected error) with one line on stderr saying what to do; ``--debug`` (or the
    environment variable ``WETCONTACT_DEBUG=1``) adds the traceback.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    end = argv.index("--") if "--" in argv else len(argv)
    debug = "--debug" in argv[:end] or os.environ.get("WETCONTACT_DEBUG", "") not in ("", "0")
    argv = [a for i, a in enumerate(argv) if i >= end or a != "--debug"]  # anywhere on the line
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error already printed
        return exc.code if isinstance(exc.code, int) else 2
    except KeyboardInterrupt:  # Ctrl-C while the parser's modules load (numpy, scipy)
        sys.stderr.write("wetcontact: interrupted before any work\n")
        return 130
    previous = _catch_sigterm()
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _warning_line
            return _dispatch(args)
    except KeyboardInterrupt:
        sys.stderr.write("wetcontact: interrupted; everything saved before is in the store\n")
        return 130
    except Terminated:
        sys.stderr.write("wetcontact: terminated; everything saved before is in the store\n")
        return 143
    except BrokenPipeError:  # the reader of stdout went away (| head): stop quietly
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except Exception as exc:  # noqa: BLE001 - the boundary: every failure is one line
        code, line = error_line(exc)
        if debug:
            traceback.print_exc(file=sys.stderr)
        sys.stderr.write(line + "\n")
        return code
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


class Terminated(BaseException):
    """SIGTERM, raised in the main thread so that a command unwinds as on Ctrl-C: a sweep
    saves what it computed and shuts its local cluster down (a terminated ``--workers 2``
    sweep left the cluster's semaphores to the resource tracker, which printed two
    warning lines about them)."""


def _catch_sigterm() -> Any:
    """Raise :class:`Terminated` on SIGTERM (once: a second SIGTERM acts as it did before);
    return the previous handler, or ``None`` where it cannot be set (not the main thread,
    or SIGTERM ignored by the parent)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    previous = signal.getsignal(signal.SIGTERM)
    if previous is signal.SIG_IGN or previous is None:
        return None

    def terminate(signum: int, frame: object) -> None:
        signal.signal(signal.SIGTERM, previous)
        raise Terminated()

    signal.signal(signal.SIGTERM, terminate)
    return previous


def _dispatch(args: argparse.Namespace) -> int:
    if args.command == "models":
        return _models_json() if args.json else _models()
    if args.command == "solve":
        return _solve(args)
    if args.command == "collide":
        from wetcontact.collide.command import run as run_collide

        return run_collide(args)
    if args.command == "sweep":
        return _sweep(args)
    if args.command == "compare":
        return _compare(args)
    if args.command == "export":
        return _export(args)
    if args.command == "calibrate":
        return _calibrate(args)
    if args.command == "run":
        from wetcontact.report import run_all

        path = run_all(cases=args.cases, out=args.out,
                       mode="quick" if args.quick else "full" if args.full else "default",
                       resume=args.resume, bench=args.bench)
        print(f"wetcontact run: wrote {path}")  # the last line: where the report is
        return 0
    raise InputError(f"unknown command {args.command!r}; see wetcontact --help")


#: errors a user fixes by choosing another path (exit 2), and the hint for each
_PATH_ERRORS: dict[int, str] = {
    errno.EEXIST: "choose a new name or remove it",
    errno.ENOENT: "check the path",
    errno.EACCES: "choose a folder you can write to",
    errno.EPERM: "choose a folder you can write to",
    errno.EROFS: "choose a folder on a writable file system",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.EISDIR: "give a file, not a folder",
    errno.ENOSPC: "free some space or choose another folder",
    getattr(errno, "EDQUOT", errno.ENOSPC): "free some space or choose another folder",
    errno.ENAMETOOLONG: "use a shorter path or name",
}


def error_line(exc: BaseException) -> tuple[int, str]:
    """Exit code and the one line a user sees for ``exc`` (no traceback).

    An unexpected error raised while a full disk was being handled (HDF5's ``RuntimeError:
    Slist already enabled?`` from a second write after a failed one) is reported as that
    full disk: the ``OSError`` in its chain of causes, exit 2.
    """
    if not isinstance(exc, InputError | SolverError | OSError):
        exc = _full_disk_cause(exc) or exc
    if isinstance(exc, InputError):
        return 2, f"wetcontact: error: {_one_line(exc, limit=1200)}"
    if isinstance(exc, SolverError):
        return 1, f"wetcontact: solver failed: {_one_line(exc)}"
    if isinstance(exc, OSError):
        where = " ".join(repr(str(f)) if len(str(f)) <= 200 else repr(f"{str(f)[:200]}...")
                         for f in (exc.filename, exc.filename2) if f is not None)
        what = exc.strerror or _one_line(exc) or type(exc).__name__
        if exc.errno in _PATH_ERRORS:
            return 2, (f"wetcontact: error: {where + ': ' if where else ''}{what}; "
                       f"{_PATH_ERRORS[exc.errno]}")
        return 1, (f"wetcontact: error: {where + ': ' if where else ''}{what} "
                   f"({type(exc).__name__}); rerun with --debug for the traceback")
    if isinstance(exc, MemoryError):
        return 1, ("wetcontact: error: out of memory; use fewer gaps or a coarser preset "
                   "(rerun with --debug for the traceback)")
    return 1, (f"wetcontact: internal error ({type(exc).__name__}: {_one_line(exc)}); "
               "rerun with --debug for the traceback and report it")


def _full_disk_cause(exc: BaseException) -> OSError | None:
    """The ENOSPC or EDQUOT ``OSError`` among the causes and contexts of ``exc``, if any."""
    full = (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))
    seen: set[int] = set()
    cur: BaseException | None = exc
    while cur is not None and id(cur) not in seen:
        seen.add(id(cur))
        if isinstance(cur, OSError) and cur.errno in full:
            return cur
        cur = cur.__cause__ or cur.__context__
    return None


def _warning_line(message: Warning | str, category: type[Warning], filename: str,
                  lineno: int, file: object = None, line: str | None = None) -> None:
    """A warning (e.g. numpy's overflow) as one line on stderr, not two with source code."""
    sys.stderr.write(f"wetcontact: warning: {category.__name__}: {_one_line(message)} "
                     f"({Path(filename).name}:{lineno})\n")


def _one_line(exc: BaseException | Warning | str, limit: int = 300) -> str:
    """The exception's message on one line, at most ``limit`` characters."""
    text = " ".join(str(exc).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


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

    models = sorted(load_all().values(), key=lambda m: (m.level, m.name))
    rows = [(m.name, str(m.level), m.component, m.validity) for m in models]
    w = [max(len(r[i]) for r in rows + [("model", "level", "component", "")]) for i in range(3)]
    print(f"{'model':<{w[0]}}  {'level':<{w[1]}}  {'component':<{w[2]}}  validity")
    for r, m in zip(rows, models, strict=True):
        print(f"{r[0]:<{w[0]}}  {r[1]:<{w[1]}}  {r[2]:<{w[2]}}  {r[3]}")
        print(f"{'':<{w[0]}}  {'':<{w[1]}}  {'':<{w[2]}}  source: {m.source}")
    from wetcontact.calibrate import FAMILIES

    print("\nclosure families to refit (wetcontact calibrate STUDY --closure FAMILY; then "
          "solve --model FAMILY --coefficients FILE.json):")
    wf = max(len(name) for name in FAMILIES)
    for fam in FAMILIES.values():
        print(f"{fam.name:<{wf}}  {fam.target:<9}  {fam.description}; {fam.kind} {fam.amount}"
              + (" (equal spheres)" if fam.equal else ""))
    return 0


def _models_json() -> int:
    """``wetcontact models --json``: one object, model name -> level, component, validity,
    source and declared convergence order (None for a closed form), in the listing's order."""
    from wetcontact.models import load_all

    models = sorted(load_all().values(), key=lambda m: (m.level, m.name))
    print(json.dumps({m.name: {"level": m.level, "component": m.component,
                               "validity": m.validity, "source": m.source, "order": m.order}
                      for m in models}))
    return 0


def _solve(args: argparse.Namespace) -> int:
    from wetcontact import select
    from wetcontact.models import get_model, model_instead
    from wetcontact.scene import TOLERANCE_RANGE, load_case

    if args.model is not None and not args.model.strip():  # '' fell back to the case's model
        raise InputError(f"--model = {args.model!r}; allowed: a model name (see `wetcontact "
                         "models`)")
    with quiet_validation():
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

            with quiet_validation():
                model = load_coefficients(coefficients, family=name)
            why = f"coefficients from {coefficients}"
        elif args.model:
            try:
                model = get_model(name)
            except InputError as exc:
                from wetcontact.calibrate import FAMILIES

                if name not in FAMILIES:
                    raise InputError(f"{exc}; or, with --coefficients FILE.json, a closure "
                                     "family: " + ", ".join(FAMILIES)) from None
                raise InputError(f"--model {name!r} is a closure family to refit: give "
                                 "--coefficients FILE.json (from wetcontact calibrate), or "
                                 "one of the models of 'wetcontact models'") from None
        else:  # the case file's fidelity.model
            try:
                model = get_model(name)
            except InputError as exc:
                raise InputError(f"{args.case}: field 'fidelity.model': {exc}") from None
        if args.save_fields is not None:
            if not model.saves_fields:
                raise InputError(f"--save-fields: model '{model.name}' has no fields to "
                                 "save; use a field solver (stokes)")
            opts["save_fields"] = str(writable_folder(args.save_fields, "--save-fields"))
        with Progress(f"{scene.name} with model '{model.name}'"):
            curve = model.force(scene, preset=preset, **opts)
        for comp, arr in (("viscous", curve.force_viscous),
                          ("capillary", curve.force_capillary)):
            names[comp] = model.name if arr is not None else None
        if note := curve.diagnostics.get("past_rupture"):
            sys.stderr.write(f"wetcontact: note: {note}\n")
        if note := curve.diagnostics.get("outside_stated_validity"):
            alt = model_instead(scene, model.component, exclude=model.name)
            sys.stderr.write(f"wetcontact: warning: model '{model.name}' is used outside its "
                             f"stated validity ({note})"
                             + (f"; model '{alt}' applies\n" if alt else "\n"))
        if note := curve.diagnostics.get("outside_domain"):
            sys.stderr.write(f"wetcontact: warning: model '{model.name}' gives NaN at gaps "
                             f"{_nan_gaps(curve)} m: {note}\n")
    else:
        tol = args.tol if args.tol is not None else scene.tolerance
        lo, hi = TOLERANCE_RANGE
        if args.tol is not None and not lo < args.tol < hi:
            raise InputError(f"--tol = {args.tol!r}; allowed: ({lo:g}, {hi:g}) relative")
        if tol is None:
            raise InputError(f"{args.case}: no model: give --model, --tol, or fidelity.model / "
                             "fidelity.tolerance in the case file")
        if args.save_fields is not None:
            raise InputError("--save-fields needs --model (a field solver, e.g. stokes)")
        with Progress(f"{scene.name} (models chosen per force component at tol {tol:g})"):
            curve, sel = select.solve(scene, tol, preset=args.preset)
        preset, why = args.preset or "per component", sel.reason
        names = {c: (sel.choices[c].model.name if c in sel.choices else None)
                 for c in select.COMPONENTS}
        for ch in sel.choices.values():
            if not ch.met:
                sys.stderr.write(f"wetcontact: warning: {ch.component} force: {ch.reason}\n")
        if note := curve.diagnostics.get("past_rupture"):
            sys.stderr.write(f"wetcontact: note: {note}\n")
    if args.json:
        out = curve.to_json_dict()
        out["model_viscous"] = names.get("viscous")
        out["model_capillary"] = names.get("capillary")
        out["selection"] = why
        if curve.diagnostics.get("outside_domain"):  # NaN (warned above) as JSON null
            out = {k: ([None if isinstance(x, float) and math.isnan(x) else x for x in v]
                       if isinstance(v, list) else v) for k, v in out.items()}
        try:
            text = json.dumps(out, allow_nan=False)
        except ValueError:  # a NaN in settings/diagnostics: never printed silently
            raise SolverError(f"model '{curve.model}' returned a non-finite value in its "
                              "diagnostics; rerun with --debug and report it") from None
        print(text)
    else:
        print(f"# case {scene.name}  model {curve.model} ({why}), preset {preset}, "
              f"{curve.diagnostics.get('wall_time_s', 0):.3g} s")
        cols = [("gap_m", curve.gap), ("F_viscous_N", curve.force_viscous),
                ("F_capillary_N", curve.force_capillary), ("F_total_N", curve.force_total),
                *((TEXT_EXTRAS.get(k, k), v) for k, v in curve.extras.items()
                  if k in TEXT_EXTRAS or curve.force_total is None)]
        cols = [(n, c) for n, c in cols if c is not None]
        print("  ".join(f"{n:>14}" for n, _ in cols))
        for i in range(curve.gap.size):
            print("  ".join(f"{c[i]:>14.6e}" for _, c in cols))
    return 0


def _nan_gaps(curve: ForceCurve, shown: int = 6) -> str:
    """The gaps (m) where ``curve`` has a NaN force or extra, as text: the first ``shown``
    of them, then how many more."""
    import numpy as np

    arrays = [a for a in (curve.force_viscous, curve.force_capillary, *curve.extras.values())
              if a is not None]
    bad = curve.gap[np.any([np.isnan(a) for a in arrays], axis=0)]
    text = ", ".join(f"{g:.6g}" for g in bad[:shown])
    return text + (f" and {bad.size - shown} more" if bad.size > shown else "")


TEXT_EXTRAS = {"rupture_distance": "rupture_distance_m"}
"""Extras the text table of ``solve`` shows beside the forces, with their column names
(every extra, under its own name where it has none here, when the model gives no force);
``--json`` gives them all."""


def writable_folder(path: Path, flag: str) -> Path:
    """``path`` as an existing folder the process can write to, checked before any solve.

    Creates it (and its parents) when missing; a file in the way, a missing permission or a
    full disk is an :class:`InputError` naming ``flag`` and the path.
    """
    from wetcontact.fileio import atomic_write_text

    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{flag} {str(path)!r}: exists and is not a folder; give a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".wetcontact-write-test"
        atomic_write_text(probe, "")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"{flag} {str(path)!r}: cannot write there "
                         f"({exc.strerror or type(exc).__name__}); choose a writable folder"
                         ) from None
    return path


#: seconds between progress lines on a non-terminal stderr (a spinner refreshes faster)
PROGRESS_EVERY = 5.0
_SPIN = "|/-\\"


class Progress:
    """Progress of a slow call on stderr, never on stdout (so ``--json`` stays clean).

    On a terminal: a spinner line with the elapsed time, redrawn in place and erased at the
    end. Otherwise (logs, pipes): one line every :data:`PROGRESS_EVERY` seconds. A call
    shorter than that prints nothing. Both are :class:`wetcontact.progress.Ticker` lines.
    """

    def __init__(self, what: str, stream=None):
        self.what, self.stream = what, stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self._spin = 0
        every = min(PROGRESS_EVERY, 0.25) if self.tty else PROGRESS_EVERY
        first = min(PROGRESS_EVERY, 1.0) if self.tty else PROGRESS_EVERY
        self._ticker = Ticker(self._line, every, self.stream, first=first)

    def _line(self) -> str:
        dt = time.monotonic() - self.t0
        if not self.tty:
            return f"wetcontact: still solving {self.what}, {dt:.0f} s\n"
        self._spin += 1
        spin = _SPIN[(self._spin - 1) % 4]
        return f"\rwetcontact: solving {self.what} {spin} {dt:.0f} s\x1b[K"

    def __enter__(self) -> Progress:
        self.t0 = time.monotonic()
        self._ticker.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._ticker.stop()
        if self.tty and self._ticker.ticks:
            self.stream.write("\r\x1b[K")
            self.stream.flush()


def _load_study(path: Path) -> Study:
    """The study at ``path``, with progress while its bridges' rupture distances are
    solved (0.5 s each, the first time: they are cached)."""
    from wetcontact.study import load_study

    with Progress(f"loading {path} (and the rupture distances its gaps are scaled by, "
                  "if any)"), quiet_validation():
        return load_study(path)


@contextlib.contextmanager
def quiet_validation() -> Iterator[None]:
    """Read and validate input without Python's ``RuntimeWarning`` lines (numpy's overflow
    or invalid value): validation checks every value it computes and refuses a bad one in
    one line, so a warning printed before that line is noise (an error was two to four
    lines). Warnings of the solve itself are still shown."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


def _sweep(args: argparse.Namespace) -> int:
    from wetcontact.store import Store
    from wetcontact.sweep import sweep

    if args.wait < 0 or args.wait != args.wait:
        raise InputError(f"--wait = {args.wait!r}; allowed: seconds >= 0")
    writable_file(args.store, "--store")  # before the study's rupture distances are solved
    store = Store(args.store)
    store.check_writable()  # a read-only or foreign store too (again under the lock)
    study = _load_study(args.study)
    res = sweep(study.points(), store, workers=args.workers,
                scheduler=args.scheduler, progress=True, retry_failed=args.retry_failed,
                lock_timeout=args.wait, keep_curves=False)
    summary = res.summary(study.name)
    # a sweep in which every point failed (e.g. a model that refuses the study's scenes)
    # computed nothing: a script must see it, so exit 1 (some failures keep exit 0)
    code = 1 if summary["points"] and summary["failed"] == summary["points"] else 0
    every = (f"wetcontact: error: every one of the {summary['points']} points failed "
             "(reasons: without --json, above; a model's refusals are also kept in the "
             "store, a cluster's failures are not); nothing was computed\n")
    if args.json:
        print(json.dumps(summary))
        if code:
            sys.stderr.write(every)
        return code
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
    if code:
        sys.stderr.write(every)
    return code


def _export(args: argparse.Namespace) -> int:
    if args.format == "yade":
        return _export_yade(args)
    if args.format == "yade-liquid":
        from wetcontact.export.yade_liquid import write_yade_liquid

        parent = args.out if args.out.is_dir() else args.out.parent
        if not parent.is_dir():
            raise InputError(f"--out {args.out}: the folder {parent} does not exist")
        info = write_yade_liquid(args.out)
        print(json.dumps(info) if args.json else f"{info['out']}: yade-liquid, "
              f"{info['bytes']} bytes")
        return 0
    if args.format == "csv":
        from wetcontact.export.csv import write_csv
        from wetcontact.store import Store

        if not args.store.is_file():
            raise InputError(f"--store {args.store}: no such store; run `wetcontact sweep` "
                             "first")
        if not args.out.parent.is_dir():
            raise InputError(f"--out {args.out}: the folder {args.out.parent} does not exist")
        writable_file(args.out, "--out", make_folders=False)
        t0 = time.perf_counter()
        study = _load_study(args.study)
        counts = write_csv(study.points(), study.axes, Store(args.store), args.out)
        if args.json:
            print(json.dumps({"format": "csv", "out": str(args.out), **counts,
                              "wall_time_s": round(time.perf_counter() - t0, 4)}))
        else:
            print(f"{args.out}: {counts['rows']} rows ({counts['ok']} ok, "
                  f"{counts['no-bridge']} no-bridge, {counts['failed']} failed, "
                  f"{counts['missing']} missing)")
        return 0
    return _export_closures(args)


def _export_closures(args: argparse.Namespace) -> int:
    """``export json|python|c``: write the file, print one line (or one JSON object)."""
    from wetcontact.export.calibration_json import write_json
    from wetcontact.export.closures import capillary_source

    parent = args.out if args.out.is_dir() else args.out.parent
    if not parent.is_dir():
        raise InputError(f"--out {args.out}: the folder {parent} does not exist")
    t0 = time.perf_counter()
    if args.format == "json":
        info = write_json(args.out, closure=args.closure, coefficients=args.coefficients)
    elif args.format in ("python", "c"):
        from wetcontact.export.c_header import write_header
        from wetcontact.export.python_module import write_module
        from wetcontact.export.refits import read_refits

        write = write_module if args.format == "python" else write_header
        refits = read_refits(args.refit)  # every file checked before the shipped tables
        info = write(args.out, capillary_source(args.capillary, args.rupture), refits)
    else:
        raise InputError(f"export format = {args.format!r}; allowed: csv, json, python, c")
    info["wall_time_s"] = round(time.perf_counter() - t0, 4)
    if args.json:
        print(json.dumps(info))
    else:
        print(f"{info['out']}: {args.format}, {info['bytes']} bytes in "
              f"{info['wall_time_s']:.3g} s" + (f"; capillary: {info['capillary']}"
                                                if "capillary" in info else ""))
    return 0


def _compare(args: argparse.Namespace) -> int:
    from wetcontact.fileio import safe_stem
    from wetcontact.report import compare_case

    models = None
    if args.models is not None:
        models = [m.strip() for m in args.models.split(",") if m.strip()]
        if not models:
            raise InputError(f"--models = {args.models!r}; allowed: model names separated "
                             "by commas (see `wetcontact models`)")
    if args.out is None:
        from wetcontact.scene import load_case

        with quiet_validation():
            args.out = Path(f"compare-{safe_stem(load_case(args.case).name)}")
    writable_folder(args.out, "--out")  # before any curve is solved
    with quiet_validation():
        cmp = compare_case(args.case, args.out, models=models, preset=args.preset,
                           workers=args.workers, progress=True)
    res = cmp.result
    if args.json:
        def finite(v: object) -> object:
            return None if isinstance(v, float) and v != v else v

        print(json.dumps({"case": res.scene.name, "references": cmp.references,
                          "rows": [{k: finite(v) for k, v in r.items()} for r in cmp.rows],
                          "not_applicable": cmp.not_applicable, "failed": res.failures,
                          "files": [str(f) for f in cmp.files], "counts": cmp.counts}))
    else:
        refs = ", ".join(f"{c} {m}" for c, m in cmp.references.items()) or "none"
        print(f"# case {res.scene.name}: reference {refs}; preset {args.preset}; "
              f"{cmp.counts['computed']} curves computed, {cmp.counts['reused']} reused, "
              f"{cmp.counts['failed']} failed in {cmp.counts['wall_time_s']:.3g} s")
        print(cmp.table if cmp.rows else "no closure to compare with the reference")
        if models is not None:
            for name, why in cmp.not_applicable.items():
                print(f"not applicable: {name}: {why}")
        elif cmp.not_applicable:
            print("not applicable: " + ", ".join(cmp.not_applicable) + " (--json, or "
                  "--models NAME, gives the reason)")
        for name, why in res.failures.items():
            print(f"failed: {name}: {why}")
        print("wrote " + ", ".join(str(f) for f in cmp.files))
    if res.failures:
        raise SolverError(f"{len(res.failures)} model(s) failed on case {res.scene.name!r}: "
                          + "; ".join(f"{m}: {w}" for m, w in res.failures.items()))
    return 0


def _calibrate(args: argparse.Namespace) -> int:
    from wetcontact.calibrate import calibrate_study

    if args.seed < 0:
        raise InputError(f"--seed = {args.seed}; allowed: an integer >= 0")
    writable_file(args.out, "--out")  # before the study is loaded and its points solved
    if not args.store.exists():  # written only when points are missing: a new store then
        writable_file(args.store, "--store")
    elif args.store.is_dir():
        raise InputError(f"--store {str(args.store)!r}: a folder; allowed: an HDF5 store file")
    cal, files = calibrate_study(args.study, args.closure, args.out, args.store,
                                 workers=args.workers, held_out=args.held_out,
                                 held_out_points=args.held_out_points, seed=args.seed)
    ho = cal.held_out
    if cal.train["points"] <= cal.coefficients.size:
        sys.stderr.write(f"wetcontact: warning: {cal.train['points']} training points for "
                         f"{cal.coefficients.size} coefficients: the fit can interpolate its "
                         "training points; judge it by the held-out errors, or widen the "
                         "study's grid\n")
    print(f"{cal.family}: reference {cal.extra['reference']}, {cal.train['points']} training "
          f"points, {ho['points']} held-out points")
    for tag in ("before", "after"):
        e = ho[tag]
        where = ", ".join(f"{k} {v:.3g}" for k, v in e["max_at"].items())
        print(f"  {'published' if tag == 'before' else 'refitted':>9}: max {e['max']:.3g} "
              f"(at {where}), mean {e['mean']:.3g}, p95 {e['p95']:.3g}")
    print(f"  goal (refitted max <= published max / 3): "
          f"{'met' if cal.goal_met else 'NOT met'}")
    print("wrote " + ", ".join(str(f) for f in files))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
