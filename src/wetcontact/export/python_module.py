"""``wetcontact export python``: one numpy-only module with the calibrated closures.

The written module imports only numpy and the standard library (never wetcontact) and holds
the same functions as the C header (:mod:`wetcontact.export.c_header`), vectorised:
arguments broadcast against each other, results are float arrays (0-d for scalar input),
NaN outside the calibrated domain, 0 past rupture. It is the template
``templates/wetcontact_closures.py.in`` (placeholders ``@name@``, ``@name:spec@``, as the
header's: :mod:`wetcontact.export.templates`) filled with the coefficient tables and domain
limits.

Its ``calibrated-capillary`` evaluator is the package's own code, not a copy: the source of
:mod:`~wetcontact.reduced_models.calibrated_capillary.coordinates` and
:mod:`~wetcontact.reduced_models.calibrated_capillary.kernel` after their imports, spliced
in verbatim (:func:`evaluator_source`), with the tables in the package data's layout
(:func:`_tables`), so that the module evaluates exactly what the package's model does. It
is spliced into the one file, not written as a second module beside it, so that the export
stays one self-contained file that a DEM user copies and imports (``--out FILE.py``), with
no import path between files to keep; :func:`check_names` (run by the tests) refuses a name
bound twice in that shared namespace. The transfer fraction's evaluation is likewise the package's
functions verbatim (:mod:`wetcontact.export.transfer_fraction`).
"""

from __future__ import annotations

import ast
import inspect
import math
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact import __version__
from wetcontact.export.c_header import (
    FUNCTIONS,
    _bridge_fields,
    bands_text,
    capillary_fields,
    held_out_lines,
    onset_text,
)
from wetcontact.export.closure_tables import (
    PAIR_TWO_ANGLES,
    TWO_ANGLES,
    CapillaryBand,
    CapillaryPart,
    CapillarySource,
    RefitTable,
    TensorTrain,
)
from wetcontact.export.closures import immersed_tables, usage_text
from wetcontact.export.refits import REFIT_FORMS, comment_lines, python_text
from wetcontact.export.templates import render
from wetcontact.fileio import atomic_write_text
from wetcontact.reduced_models.calibrated import viscous_table
from wetcontact.reduced_models.calibrated_capillary import (
    ONSET_KEY,
    RIDGE_QUADRATIC,
    UPPER_PAST_RIDGE,
    coordinates,
    kernel,
)

MODULE_NAME = "wetcontact_closures.py"

TEMPLATE = "wetcontact_closures.py.in"
"""The module's template (:mod:`wetcontact.export.templates`): the numpy code with the
tables, domain limits, documentation figures and the spliced evaluator as placeholders."""
EVALUATOR = (coordinates, kernel)
"""The modules whose source (after their imports) is the written module's
``calibrated-capillary`` evaluator, in this order: the kernel imports the coordinates."""


def module_text(source: CapillarySource, refits: Sequence[RefitTable] = ()) -> str:
    """The text of the numpy-only module for the shipped tables and ``source``, plus one
    function per refit of ``refits`` (:mod:`wetcontact.export.refits`)."""
    imm = immersed_tables()
    w, ss = imm["sphere-wall"], imm["sphere-sphere"]
    if w["log_range"] != ss["log_range"]:
        raise ValueError("immersed tables with different ranges: the module assumes one")
    lo, hi = w["log_range"]
    cap, rup = source.force, source.rupture
    (v_lo, v_hi), (t_lo, t_hi) = rup.domain["v_star"], rup.domain["theta_deg"]
    sc_lo, sc_hi = cap.domain["s_over_sc"]
    bw, bs = viscous_table()["bridge"]["sphere-wall"], viscous_table()["bridge"]["sphere-sphere"]
    br = _bridge_fields(bw, bs)
    br.update(br_wall=_list(bw["coefficients"]), br_ss=_list(bs["coefficients"]))
    parts = source.table.parts
    doc = "".join("\n" + line for line in [""] + comment_lines(refits, "python")
                  ) if refits else ""
    names = "".join(f',\n           "{REFIT_FORMS[t.family].py_name}"' for t in refits)
    imports, evaluator = evaluator_source()
    text = render(TEMPLATE, {
        **br, "refit_doc": doc, "refit_all": names, "imports": imports, "kernel": evaluator,
        **capillary_fields(source), "usage": usage_text(br["bh_lo"], br["bh_hi"], "python"),
        "cap_held_out": _fill("; ".join(held_out_lines(source)) + "."),
        "cap_tables": _tables(parts), "bands": bands_text(parts.get(TWO_ANGLES)),
        "bands_ss": bands_text(parts.get(PAIR_TWO_ANGLES)),
        "onset": onset_text(parts.get(TWO_ANGLES), ""),
        "br_err_wall": bw["held_out"]["after"]["max"],
        "br_err_ss": bs["held_out"]["after"]["max"], "version": __version__,
        "imm_err_wall": w["held_out"]["max"], "imm_err_ss": ss["held_out"]["max"],
        "s_lo": math.exp(lo), "s_hi": math.exp(hi),
        "refit_label": _fill(source.refit_label + "."), "v_lo": v_lo, "v_hi": v_hi,
        "t_lo": t_lo, "t_hi": t_hi, "sc_lo": sc_lo, "sc_hi": sc_hi,
        "cheb_wall": _list(w["chebyshev"]), "cheb_ss": _list(ss["chebyshev"]),
        "log_lo": repr(lo), "log_hi": repr(hi), "s_lo_r": repr(math.exp(lo)),
        "s_hi_r": repr(math.exp(hi)), "v_lo_r": repr(v_lo), "v_hi_r": repr(v_hi),
        "t_lo_r": repr(t_lo), "t_hi_r": repr(t_hi), "sc_lo_r": repr(sc_lo),
        "sc_hi_r": repr(sc_hi), "lian": _list(rup.coefficients),
        "willett": _list(cap.coefficients)}) + _transfer_fraction() + python_text(refits)
    return text


def _transfer_fraction() -> str:
    """``transfer_fraction`` and ``dynamic_rupture_ratio`` (their own modules,
    :mod:`wetcontact.export.transfer_fraction`, :mod:`wetcontact.export.dynamic_rupture`)."""
    from wetcontact.export.dynamic_rupture import python_text as dynamic_rupture_py
    from wetcontact.export.transfer_fraction import python_text as transfer_fraction_py

    return transfer_fraction_py() + dynamic_rupture_py()


def _fill(text: str) -> str:
    """``text`` wrapped to 88 columns for the module's docstring (names kept whole)."""
    return textwrap.fill(text, 88, break_on_hyphens=False)


def evaluator_source() -> tuple[str, str]:
    """The :data:`EVALUATOR` modules' imports (the standard library's and numpy's, each once,
    ``from __future__`` first; the package's are dropped: its modules are spliced in
    together) and their source after the imports, verbatim; a :class:`ValueError` where a
    module imports a name of the package that the splice does not define, or imports below
    its first statement."""
    imports: list[str] = []
    bodies, defined, needed = [], set(), set()
    for module in EVALUATOR:
        src = inspect.getsource(module)
        tree = ast.parse(src)
        body = tree.body[1:] if ast.get_docstring(tree) is not None else tree.body
        head = [n for n in body if isinstance(n, ast.Import | ast.ImportFrom)]
        if body[:len(head)] != head:
            raise ValueError(f"{module.__name__}: an import below its first statement")
        for n in head:
            if isinstance(n, ast.ImportFrom) and (n.module or "").startswith("wetcontact"):
                needed.update(a.asname or a.name for a in n.names)
            elif (line := ast.get_source_segment(src, n)) not in imports:
                imports.append(line)
        lines = src.splitlines()
        bodies.append("\n".join(lines[head[-1].end_lineno:]).strip("\n"))
        defined.update(_top_names(tree))
    if needed - defined:
        raise ValueError(f"the evaluator imports {sorted(needed - defined)} from the package, "
                         "which the spliced modules do not define")
    imports.sort(key=lambda line: not line.startswith("from __future__"))
    return "\n".join(imports), "\n\n\n".join(bodies)


def _top_names(tree: ast.Module) -> list[str]:
    """The names a module binds at its top level (definitions and assignments)."""
    out = []
    for n in tree.body:
        if isinstance(n, ast.FunctionDef | ast.ClassDef):
            out.append(n.name)
        elif isinstance(n, ast.Assign | ast.AnnAssign):
            for t in (n.targets if isinstance(n, ast.Assign) else [n.target]):
                out.extend(x.id for x in ast.walk(t) if isinstance(x, ast.Name))
    return out


def check_names(text: str) -> None:
    """Refuse a written module that binds a top-level name twice (the spliced evaluator, the
    template and the appended functions share one namespace), unless both bind the same
    literal (``V_RANGE`` of the capillary coordinates and of the transfer fraction). The
    tests call it on every refit's module (parsing 4 MB of tables takes about a second, so
    the export itself does not)."""
    seen: dict[str, Any] = {}
    for n in ast.parse(text).body:
        if not isinstance(n, ast.FunctionDef | ast.ClassDef | ast.Assign | ast.AnnAssign):
            continue
        try:
            literal = ("literal", ast.literal_eval(n.value)) if isinstance(
                n, ast.Assign | ast.AnnAssign) and n.value is not None else None
        except ValueError:
            literal = None
        for name in _top_names(ast.Module(body=[n], type_ignores=[])):
            if name in seen and (literal is None or seen[name] != literal):
                raise ValueError(f"the exported module binds {name!r} twice")
            seen[name] = literal


def _tables(parts: dict[str, CapillaryPart]) -> str:
    """The generated geometries as Python source: a dict by table key in the package data's
    layout (what :func:`~wetcontact.reduced_models.calibrated_capillary.kernel.table_star`
    reads), of a piece only what is evaluated (its tensor trains where it has them)."""
    out = []
    for kind, part in parts.items():
        if part.bands:
            onset = ("" if part.onset is None else
                     f'{ONSET_KEY!r}: {{"chebyshev": {_array(part.onset)}}},\n    ')
            text = (f'{{{onset}"bands": [\n    ' + ",\n    ".join(
                _section(h, f'"theta_sphere_deg": ({h.theta_sphere_lo!r}, '
                         f'{h.theta_sphere_hi!r}),\n    ') for h in part.bands) + "]}")
        else:
            text = _section(part, "")
        out.append(f"{kind!r}: {text}")
    return "{\n" + ",\n".join(out) + "}"


def _section(sec: CapillaryPart | CapillaryBand, lead: str) -> str:
    """One table (a geometry's, or a band's; ``lead``: the band's range) as Python source:
    its split series and its pieces."""
    split = "None" if sec.split is None else f'{{"chebyshev": {_array(sec.split)}}}'
    pieces = []
    for p in sec.pieces:
        fields = [f'"theta_deg": ({p.theta_lo!r}, {p.theta_hi!r})']
        fields += [f'"theta_map": {RIDGE_QUADRATIC!r}'] if p.quadratic else []
        fields += [f"{UPPER_PAST_RIDGE!r}: True"] if p.upper_past_ridge else []
        fields += ([f'"rupture": {_array(p.rupture)}'] if p.rupture_train is None else
                   [f'"rupture_train": {_train(p.rupture_train)}'])
        fields += ([f'"force_left": {_array(p.force_left)}',
                    f'"force_right": {_array(p.force_right)}'] if p.force_train is None else
                   [f'"force_train": {_train(p.force_train)}'])
        pieces.append("{\n        " + ",\n        ".join(fields) + "}")
    return f'{{{lead}"theta_split": {split},\n    "pieces": [' + ", ".join(pieces) + "]}"


def _array(arr: np.ndarray) -> str:
    """An array as Python source, ``np.array([...]).reshape(shape)``."""
    return f"np.array({_list(arr.ravel(), 4)}).reshape({arr.shape})"


def _train(train: TensorTrain) -> str:
    """A tensor train as Python source, ``{"order": (...), "cores": [...]}`` (the kernel's
    :func:`~wetcontact.reduced_models.calibrated_capillary.kernel.train_sum`)."""
    cores = ",\n        ".join(_array(g) for g in train.cores)
    return f'{{"order": {train.order!r}, "cores": [\n        {cores}]}}'


def _list(values: Any, per_line: int = 3) -> str:
    vals = [repr(float(v)) for v in values]
    lines = [", ".join(vals[i:i + per_line]) for i in range(0, len(vals), per_line)]
    return "[\n    " + ",\n    ".join(lines) + "]"


def write_module(out: str | Path, source: CapillarySource,
                 refits: Sequence[RefitTable] = ()) -> dict[str, Any]:
    """Write the module to ``out`` (a ``.py`` file, or a folder for ``wetcontact_closures.py``),
    with one ``refit_<family>`` function per refit of ``refits``."""
    out = Path(out)
    if out.is_dir():
        out = out / MODULE_NAME
    text = module_text(source, refits)
    atomic_write_text(out, text)
    return {"format": "python", "out": str(out), "bytes": len(text.encode()),
            "functions": [f.removeprefix("wc_") for f in FUNCTIONS]
            + [REFIT_FORMS[t.family].py_name for t in refits],
            "capillary": source.label}
