"""``wetcontact export c``: one header-only C99 file, ``wetcontact_closures.h``.

No dependency but libm (link with ``-lm``). The header is the template
``templates/wetcontact_closures.h.in`` (package data), a C file whose coefficient tables,
domain limits and comment figures are placeholders ``@name@`` or ``@name:spec@`` (a
:func:`format` spec, e.g. ``@s_lo:.6g@``; ``@`` occurs nowhere else in the header, so C's
braces stay as they are), filled by :func:`wetcontact.export.templates.render`; the
generator writes no logic of its own. The functions and their domain are those of
:mod:`wetcontact.export.closures`; the tests compile the header with
``cc -std=c99 -Wall -Werror`` and compare it with the package's evaluation.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact import __version__
from wetcontact.export.closure_tables import (
    ONSET_TEXT,
    PAIR_TWO_ANGLES,
    TWO_ANGLES,
    CapillaryPart,
    CapillarySource,
    RefitTable,
    TensorTrain,
    sphere_end_text,
)
from wetcontact.export.closures import immersed_tables, usage_text
from wetcontact.export.dynamic_rupture import c_text as dynamic_rupture_c
from wetcontact.export.refits import REFIT_FORMS, TARGET_ARGS, c_text, comment_lines
from wetcontact.export.templates import render
from wetcontact.export.transfer_fraction import c_text as transfer_fraction_c
from wetcontact.fileio import atomic_write_text
from wetcontact.reduced_models.calibrated import viscous_table

HEADER_NAME = "wetcontact_closures.h"
FUNCTIONS = ("wc_viscous_force_immersed", "wc_viscous_force_bridge", "wc_capillary_force",
             "wc_rupture_distance", "wc_capillary_force_refit", "wc_rupture_distance_refit",
             "wc_transfer_fraction", "wc_dynamic_rupture_ratio")
TEMPLATE = "wetcontact_closures.h.in"
"""The header's template (:mod:`wetcontact.export.templates`): the C text with the tables,
domain limits and comments as placeholders."""


def c_array(values: Any, per_line: int = 4, indent: int = 8) -> str:
    """Doubles as a C initializer, each at full precision (shortest round-trip repr)."""
    vals = [repr(float(v)) for v in values]
    for v in vals:
        if not math.isfinite(float(v)):
            raise ValueError(f"non-finite coefficient {v} in an exported table")
    lines = [", ".join(vals[i:i + per_line]) for i in range(0, len(vals), per_line)]
    pad = "\n" + " " * indent
    return "{" + pad + ("," + pad).join(lines) + "}"


def _nested(k: Any) -> str:
    """A (4, 4, 3) table as a nested C initializer."""
    rows = []
    for i in range(4):
        inner = ", ".join("{" + ", ".join(repr(float(k[(i * 4 + j) * 3 + m])) for m in range(3))
                          + "}" for j in range(4))
        rows.append("{" + inner + "}")
    return "{\n        " + ",\n        ".join(rows) + "}"


def header_text(source: CapillarySource, refits: Sequence[RefitTable] = ()) -> str:
    """The text of ``wetcontact_closures.h`` for the shipped immersed tables and ``source``,
    plus one function per refit of ``refits`` (:mod:`wetcontact.export.refits`)."""
    imm = immersed_tables()
    w, ss = imm["sphere-wall"], imm["sphere-sphere"]
    if w["log_range"] != ss["log_range"]:
        raise ValueError("immersed tables with different ranges: the header assumes one")
    lo, hi = w["log_range"]
    cap, rup = source.force, source.rupture
    (v_lo, v_hi), (t_lo, t_hi) = rup.domain["v_star"], rup.domain["theta_deg"]
    if cap.domain["v_star"] != rup.domain["v_star"] or \
            cap.domain["theta_deg"] != rup.domain["theta_deg"]:
        raise ValueError("capillary and rupture refits on different (V*, theta) domains")
    s_lo_cap, s_hi_cap = cap.domain["s_over_sc"]
    bw, bs = viscous_table()["bridge"]["sphere-wall"], viscous_table()["bridge"]["sphere-sphere"]
    br = _bridge_fields(bw, bs)
    api = "".join("\n" + textwrap.fill(
        f"double {REFIT_FORMS[t.family].c_name}("
        f"{', '.join(TARGET_ARGS[REFIT_FORMS[t.family].target])});", 88,
        initial_indent=" *   ", subsequent_indent=" *" + " " * (len(REFIT_FORMS[
            t.family].c_name) + 11)) for t in refits)
    comment = "".join(f"\n * {line}".rstrip() for line in [""] + comment_lines(refits, "c")
                      ) if refits else ""
    parts = source.table.parts.values()
    values = {
        **br, **capillary_fields(source), "refit_api": api, "refit_comment": comment,
        "usage": "\n".join(f" * {line}".rstrip() for line in usage_text(
            br["bh_lo"], br["bh_hi"], "c").splitlines()),
        "br_err_wall": bw["held_out"]["after"]["max"],
        "br_err_ss": bs["held_out"]["after"]["max"], "version": __version__,
        "imm_err_wall": w["held_out"]["max"], "imm_err_ss": ss["held_out"]["max"],
        "s_lo": math.exp(lo), "s_hi": math.exp(hi),
        "cap_held_out": "\n *     ".join(held_out_lines(source)),
        "bands": bands_text(source.table.parts.get(TWO_ANGLES)),
        "bands_ss": bands_text(source.table.parts.get(PAIR_TWO_ANGLES)),
        "onset": onset_text(source.table.parts.get(TWO_ANGLES), " *   "),
        "cap_src": Path(source.table.source).name, "cap_sha": source.table.sha256[:16],
        "label": _wrap(source.refit_label), "rup_src": Path(rup.source).name,
        "rup_sha": rup.sha256[:16], "refit_src": Path(cap.source).name,
        "refit_sha": cap.sha256[:16], "v_lo": v_lo, "v_hi": v_hi, "t_lo": t_lo,
        "t_hi": t_hi, "s_lo_cap": s_lo_cap, "s_hi_cap": s_hi_cap,
        "cap_nmax": max([max(pc.force_shape) for p in parts for pc in p.all_pieces]
                        + [max(sec.split.shape) for p in parts for sec in p.sections
                           if sec.split is not None]),
        "cap_pieces": max(len(sec.pieces) for p in parts for sec in p.sections),
        "cap_bands": max(len(p.sections) for p in parts),
        "cap_rmax": max([pc.rank for p in parts for pc in p.all_pieces
                         if pc.force_train is None]
                        + [r for p in parts for pc in p.all_pieces
                           for t in (pc.rupture_train, pc.force_train) if t is not None
                           for r in t.ranks] + [1]),
        "cap_tables": _cap_tables(source), "cap_onset": _cap_onset(source),
        "cap_onset2": _cap_onset2(source),
        "n_wall": len(w["chebyshev"]), "cheb_wall": c_array(w["chebyshev"]),
        "n_ss": len(ss["chebyshev"]), "cheb_ss": c_array(ss["chebyshev"]),
        "log_lo": lo, "log_hi": hi, "lian": c_array(rup.coefficients),
        "willett": _nested(cap.coefficients),
        "appended": "\n".join(text.lstrip("\n") for text in (
            transfer_fraction_c(), dynamic_rupture_c(),
            *([c_text(refits)] if refits else [])))}
    return render(TEMPLATE, values)


def bands_text(part: CapillaryPart | None) -> str:
    """The bands' sphere-angle ranges of a two-angle geometry, for the comments (an end at
    the onset angle as ``theta_on(V)``, then that angle's series)."""
    if part is None:
        return "not generated"
    return ", ".join(h.range_text for h in part.bands)


def onset_text(part: CapillaryPart | None, lead: str) -> str:
    """The sentence on the onset angle for the comments, its lines after the first led by
    ``lead``; empty when no band ends there."""
    if part is None or part.onset is None:
        return ""
    text = (f" {ONSET_TEXT} = sum_k o_k T_k(a) (deg, {part.onset.size} coefficients) is the "
            "sphere angle where the jump of S_c at the ridge's top appears, evaluated at the "
            "point's own a.")
    return "\n" + lead + ("\n" + lead).join(_wrap_lines(text, 84 - len(lead)))


def _cap_onset(source: CapillarySource) -> str:
    """The body of ``wc__cap_onset``: the two-angle table's onset series, summed in the
    order of k, or NAN without one."""
    part = source.table.parts.get(TWO_ANGLES)
    if part is None or part.onset is None:
        return "    (void)a;\n    return NAN;"
    n = part.onset.size
    return (f"    static const double o[{n}] = {c_array(part.onset)};\n"
            f"    double t[{n}], sum = 0.0;\n    int k;\n"
            f"    wc__cheb_rows(a, t, {n});\n"
            f"    for (k = 0; k < {n}; ++k)\n        sum += o[k] * t[k];\n    return sum;")


def _cap_onset2(source: CapillarySource) -> str:
    """The body of ``wc__cap_onset2``: the two-angle pair table's onset series over (w, a),
    row-major, or NAN without one."""
    part = source.table.parts.get(PAIR_TWO_ANGLES)
    if part is None or part.onset is None:
        return "    (void)w;\n    (void)a;\n    return NAN;"
    nw, na = part.onset.shape
    return (f"    static const double o[{part.onset.size}] = "
            f"{c_array(part.onset.ravel())};\n"
            f"    double tw[{nw}], ta[{na}], sum = 0.0, row;\n    int i, j;\n"
            f"    wc__cheb_rows(w, tw, {nw});\n    wc__cheb_rows(a, ta, {na});\n"
            f"    for (i = 0; i < {nw}; ++i) {{\n        row = 0.0;\n"
            f"        for (j = 0; j < {na}; ++j)\n            row += o[i * {na} + j] * ta[j];\n"
            f"        sum += row * tw[i];\n    }}\n    return sum;")


def capillary_fields(source: CapillarySource) -> dict[str, Any]:
    """Domain limits and held-out errors of the shipped capillary table, for the templates
    (``{x}`` for comments, ``{x_r}`` at full precision for code)."""
    t = source.table
    limits = {"cv_lo": t.v_range[0], "cv_hi": t.v_range[1], "ct_lo": t.theta_range_deg[0],
              "ct_hi": t.theta_range_deg[1], "q_lo": t.ratio_range[0],
              "q_hi": t.ratio_range[1], "lnv_lo": math.log(t.v_range[0]),
              "lnv_hi": math.log(t.v_range[1]), "w_max": t.w_max, "angle_tol": t.angle_tol}
    fields: dict[str, Any] = {}
    for k, v in limits.items():
        fields[k], fields[k + "_r"] = float(v), repr(float(v))
    return fields


GEOMETRY_NAMES = {"sphere-wall": "plane", "sphere-sphere": "sphere pairs",
                  TWO_ANGLES: "plane, two angles", PAIR_TWO_ANGLES: "sphere pairs, two angles"}
"""How the exports' comments name each ``calibrated-capillary`` geometry."""
GEOMETRY_CODES = {"sphere-wall": "WC__CAP_PLANE", "sphere-sphere": "WC__CAP_SPHERES",
                  TWO_ANGLES: "WC__CAP_PLANE2", PAIR_TWO_ANGLES: "WC__CAP_SPHERES2"}
"""The header's code of each geometry (``wc__cap_table``)."""


def held_out_lines(source: CapillarySource) -> list[str]:
    """One line per geometry: the shipped table's held-out errors, or that it is missing."""
    t = source.table
    return [f"{name}: {t.held_out_text(k)}" if k in t.parts else
            f"{name}: table not generated (NaN)" for k, name in GEOMETRY_NAMES.items()]


def _cap_tables(source: CapillarySource) -> str:
    """The body of ``wc__cap_table``: each generated geometry's tables (one, or a plane with
    two angles' bands, each with its sphere-angle range) as static arrays (a plane's with
    a leading axis of one entry) and split series (flattened row-major: a plane with two
    angles has 2-D ridge series), ``return 0`` for a missing one."""
    out = []
    for kind, code in GEOMETRY_CODES.items():
        part = source.table.parts.get(kind)
        if part is None:
            out.append(f"    if (geometry == {code})\n        return 0;  /* {kind}: not "
                       "generated */")
            continue
        for h, sec in enumerate(part.sections):
            ts = ((sec.theta_sphere_lo, sec.theta_sphere_hi) if part.bands
                  else source.table.theta_range_deg)
            what = (f"{kind}, sphere angle {sphere_end_text(ts[0])} to "
                    f"{sphere_end_text(ts[1])} deg" if part.bands else kind)
            lines = [f"    if (geometry == {code} && band == {h}) {{  /* {what} */"]
            split = "(const double *)0"
            if sec.split is not None:
                lines.append(f"        static const double split[{sec.split.size}] = "
                             f"{c_array(sec.split.ravel(), indent=12)};")
                split = "split"
            plane = kind == "sphere-wall"  # no w axis: one entry in the header's layout
            for n, p in enumerate(sec.pieces):  # only the arrays that are evaluated
                arrays = ([("rupture", p.rupture)] if p.rupture_train is None else []) + (
                    [("left", p.force_left), ("right", p.force_right)]
                    if p.force_train is None else [])
                for name, arr in arrays:
                    lines.append(f"        static const double {name}{n}[{arr.size}] = "
                                 f"{c_array(arr.ravel(), indent=12)};")
                for name, train in (("rupture", p.rupture_train), ("force", p.force_train)):
                    if train is not None:
                        lines.extend(_train_arrays(name, n, train, plane))
            # the split series' sizes, 0 for an axis it has not: (n,) in a, (n_a, n_b1) on a
            # plane with two angles, (n_w, n_a, n_b1) between spheres with two angles
            nsplit = (*(() if sec.split is None else sec.split.shape), 0, 0, 0)[:3]
            lines.append(f"        t->npieces = {len(sec.pieces)};")
            lines.append(f"        t->nsplit = {nsplit[0]};")
            lines.append(f"        t->nsplit_b = {nsplit[1]};")
            lines.append(f"        t->nsplit_c = {nsplit[2]};")
            for end, x in zip(("lo", "hi"), ts, strict=True):  # None: the onset angle
                lines.append(f"        t->ts_{end} = {0.0 if x is None else float(x)!r};")
                lines.append(f"        t->ts_{end}_onset = {int(x is None)};")
            lines.append(f"        t->split = {split};")
            null = "(const double *)0"  # a table evaluated by its train: no array
            for n, p in enumerate(sec.pieces):
                shape = (1, *p.force_shape) if plane else p.force_shape
                four = len(shape) == 5  # (w, a, b1, b2, c): b2's size set by wc__cap_set4
                ends = ["1, 0.0" if e is None else f"0, {e!r}" for e in (p.theta_lo, p.theta_hi)]
                low_rank = p.force_train is None
                factors = (f"{p.n_left + plane}, {p.rank}" if low_rank else "0, 0")
                arrays = (null if p.rupture_train else f"rupture{n}",
                          f"left{n}" if low_rank else null, f"right{n}" if low_rank else null)
                lines.append(f"        wc__cap_set(&t->piece[{n}], {ends[0]}, {ends[1]}, "
                             f"{int(p.quadratic)}, "
                             f"{', '.join(str(x) for x in shape[:3] + shape[-1:])}, "
                             f"{factors},\n                    {', '.join(arrays)});")
                if four:
                    lines.append(f"        wc__cap_set4(&t->piece[{n}], {shape[3]}, "
                                 f"{int(p.upper_past_ridge)});")
                for name, train in (("rupture", p.rupture_train), ("force", p.force_train)):
                    if train is not None:
                        lines.append(f"        wc__cap_set_train(&t->piece[{n}].{name}_train, "
                                     f"{len(train.cores)}, {name}_info{n}, {name}_cores{n});")
            lines.append("        return 1;\n    }")
            out.append("\n".join(lines))
    return "\n".join(out) + "\n    return 0;"


GAP_SLOT = 4
"""The header's slot of the gap axis c (``WC__CAP_AXIS_C``); a table's other axes are its
slots 0, 1, ... (``WC__CAP_AXIS_W`` ...), a plane with one angle's shifted by one (it has
no w)."""


def _train_arrays(table: str, n: int, train: TensorTrain, plane: bool) -> list[str]:
    """The two static arrays of piece ``n``'s tensor train of ``table`` (``rupture`` or
    ``force``), ``{table}_info{n}`` and ``{table}_cores{n}``: per core the slot of its axis
    and its shape (r_(k-1), n, r_k), and the cores row-major one after the other (``struct
    wc__cap_train``). The table's axes map to the slots of their Chebyshev rows (a plane
    with one angle's shifted past w), the force table's last, the gap axis, to
    ``WC__CAP_AXIS_C``."""
    last = len(train.order) - 1
    slots = [GAP_SLOT if table == "force" and ax == last else ax + plane
             for ax in train.order]
    info = [x for slot, g in zip(slots, train.cores, strict=True) for x in (slot, *g.shape)]
    data = np.concatenate([g.ravel() for g in train.cores])
    return [f"        static const int {table}_info{n}[{len(info)}] = "
            f"{{{', '.join(map(str, info))}}};",
            f"        static const double {table}_cores{n}[{data.size}] = "
            f"{c_array(data, indent=12)};"]


def _bridge_fields(bw: dict[str, Any], bs: dict[str, Any]) -> dict[str, Any]:
    """Coefficients and domain limits of the bridge part, named for the templates."""
    (hw_lo, hw_hi), (vw_lo, vw_hi) = bw["domain"]["s_over_h"], bw["domain"]["v_star"]
    (hs_lo, hs_hi), (vs_lo, vs_hi) = bs["domain"]["s_over_h"], bs["domain"]["v_star"]
    q_lo, q_hi = bs["domain"]["radius_ratio"]
    limits = {"bh_lo_w": hw_lo, "bh_hi_w": hw_hi, "bv_lo_w": vw_lo, "bv_hi_w": vw_hi,
              "bh_lo_s": hs_lo, "bh_hi_s": hs_hi, "bv_lo_s": vs_lo, "bv_hi_s": vs_hi,
              "bq_lo": q_lo, "bq_hi": q_hi, "bh_lo": min(hw_lo, hs_lo),
              "bh_hi": max(hw_hi, hs_hi), "bv_lo": min(vw_lo, vs_lo), "bv_hi": max(vw_hi, vs_hi)}
    fields: dict[str, Any] = {"br_wall": c_array(bw["coefficients"]),
                              "br_ss": c_array(bs["coefficients"])}
    for k, v in limits.items():  # {k:.6g} in comments, {k_r} (full precision) in code
        fields[k], fields[k + "_r"] = float(v), repr(float(v))
    return fields


def _wrap_lines(text: str, width: int) -> list[str]:
    """The words of ``text`` in lines, a word starting a new line where it would take the
    line past ``width`` characters."""
    lines, line = [], ""
    for word in text.split():
        if len(line) + len(word) + 1 > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}".strip()
    lines.append(line)
    return lines


def _wrap(text: str, width: int = 76) -> str:
    """Wrap a label into the ``!!!`` comment lines."""
    return "\n * !!!   ".join(_wrap_lines(text, width))


def write_header(out: str | Path, source: CapillarySource,
                 refits: Sequence[RefitTable] = ()) -> dict[str, Any]:
    """Write the header to ``out`` (a file, or a folder to hold ``wetcontact_closures.h``),
    with one ``wc_refit_<family>`` function per refit of ``refits``."""
    out = Path(out)
    if out.is_dir():
        out = out / HEADER_NAME
    text = header_text(source, refits)
    atomic_write_text(out, text)
    return {"format": "c", "out": str(out), "bytes": len(text.encode()),
            "functions": list(FUNCTIONS) + [REFIT_FORMS[t.family].c_name for t in refits],
            "capillary": source.label}
