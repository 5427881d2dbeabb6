"""``wetcontact export json``: a shipped or refitted calibration as one self-describing JSON.

The document holds, per part (a geometry and liquid amount with its own coefficients),
the closure's form, the coefficients, the domain they were calibrated on and the held-out
relative errors, plus units, the sign convention, what happens outside the domain, and
provenance (package and code version, the source file and its SHA-256). It is validated
against ``calibration.schema.json`` (kept in this package, :func:`schema`) before it is
written.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import json
import math
from functools import cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from wetcontact import __version__
from wetcontact.errors import InputError
from wetcontact.export.closure_tables import sphere_end_text
from wetcontact.fileio import atomic_write_text

if TYPE_CHECKING:
    from wetcontact.export.closure_tables import (
        CapillaryBand,
        CapillaryPart,
        CapillaryPiece,
        CapillaryTable,
    )

SCHEMA_FILE = "calibration.schema.json"
SIGN = ("force on the first particle along the line of centres, positive = pushing the "
        "surfaces apart (viscous resistance to approach > 0, capillary attraction < 0)")
OUTSIDE = ("outside every range in 'domain' the coefficients are not calibrated: the "
           "package refuses (ValidityError), the exported C and Python code return NaN")
UNITS = {"inputs": "SI (m, m^3, Pa s, m/s, N/m)", "output": "N (force) or m (rupture "
         "distance)", "angles": "radians inside the forms; degrees in case files and the "
         "exported functions' arguments"}

FORMS = {
    "immersed": ("F = 6 pi eta R v lambda (wall) or 6 pi eta R (v/2) lambda (equal spheres, v "
                 "the relative approach speed); lambda = q(t) (1 + s)/s (wall) or q(t) (1 + "
                 "2s)/(2s), s = S/R, q(t) = sum_k c_k T_k(t), t = (2 ln s - lo - hi)/(hi - "
                 "lo), [lo, hi] = ln of the s_over_r domain"),
    "finite-liquid": ("F = 6 pi eta R*^2 v/S (1 - x)^p [1 + d (c0 + c1 u + c2 x + c3 x u) + "
                      "d^2 (c4 + c5 u + c6 x) + d^3 (c7 + c8 u)], x = S/H, u = sqrt(x), d = "
                      "kappa H/R*, kappa = R*^3 (1/R1^3 + 1/R2^3) (1 for a wall), H the edge "
                      "gap (film thickness, or sqrt(S^2 + V/(pi R*)) for a bridge); "
                      "coefficients (p, c0, ..., c8)"),
    "bridge-near-contact": ("; near contact, 0 < x < x0 = {x0!r} (the s_over_h domain's lower "
                            "end): F = 6 pi eta R*^2 v/S (1 - x)^2 (1 + rho x/x0), rho = "
                            "phi(x0)/(1 - x0)^2 - 1, phi the factor above at the gap where "
                            "S/H = x0 (H = H0/sqrt(1 - x0^2), H0 = sqrt(V/(pi R*))): equal to "
                            "the form at x0 and tending to Reynolds' 6 pi eta R*^2 v/S as "
                            "S/H -> 0, the limit of lubrication"),
    "film-correction": ("; for films times exp(sum_ij C[i, j] T_i(a) T_j(b)), a = (2 ln(delta/R) "
                        "- ln d0 - ln d1)/(ln d1 - ln d0), b = (2 sqrt(1 - x) - sqrt(1 - x1) "
                        "- sqrt(1 - x0))/(sqrt(1 - x0) - sqrt(1 - x1)), [d0, d1] = {d}, "
                        "[x0, x1] = {x} (the correction to Stokes' flat-top film)"),
    "willett": ("F = -2 pi R sigma exp(f1 - f2 exp(f3 ln S+ + f4 ln^2 S+)), S+ = (S/2) "
                "sqrt(R/V), f_i = sum_j sum_m k[i, j, m] ln(V/R^3)^j theta^m (Willett et al. "
                "2000, eq. A1)"),
    "lian-rupture": "S_c = R ((a + b theta) V*^(1/3) + c V*^(2/3)), V* = V/R^3 (Lian et al. "
                    "1993)",
    "mikami": "F = -pi R sigma (exp(A S/R + B) + C) (Mikami et al. 1998), A, B, C in V* and "
              "theta",
    "bagheri": "Bagheri, Roy & Poeschel (2024) eqs. 24-30",
    "capillary-rupture": (
        "S_c = R_s v^(1/3) exp(sum C[i, j, k] T_i(w) T_j(a) T_k(b)) (a wall: no w axis, "
        "C[j, k]), R_s the smaller radius (the sphere's on a wall), v = V/R_s^3, r = R_l/R_s; "
        "T_n Chebyshev polynomials of the first kind; each coordinate mapped to [-1, 1] as "
        "m(x; lo, hi) = (2 x - lo - hi)/(hi - lo): a = m(ln v; ln v0, ln v1), b = m(theta_deg; "
        "t0, t1), w = m((ln r)^(1/3); 0, (ln r1)^(1/3)), [v0, v1], [t0, t1], [1, r1] the "
        "domain's v, theta_deg and radius_ratio; one contact angle theta on both solids"),
    "capillary-force": (
        "F = -2 pi sigma R_s rho (2 cos theta) exp(sum C[i, j, k, l] T_i(w) T_j(a) T_k(b) "
        "T_l(c)) for S < S_c (a wall: no w axis, C[j, k, l]), exactly 0 at and past S_c; rho "
        "= R*/R_s = r/(1 + r) (1 on a wall), c = 2 z - 1, z = sqrt(1 - ln(1 + s/eps)/ln(1 + "
        "s_c/eps)), s = S/R_s, s_c = S_c/R_s from the rupture part, eps = sqrt(v/(pi rho)); "
        "w, a, b as in the rupture part (Derjaguin's force at contact times a smooth "
        "correction)"),
    "capillary-piece": (
        "; this part covers theta from {lo} to {hi} deg (a point belongs to the first part "
        "of its geometry whose upper end is at or above its angle) and b = m(theta_deg; lo, "
        "hi) within it, where 'split' is the split angle theta_s = sum_k s_k T_k(a) (deg)"),
    "capillary-rupture-two-angles": (
        "S_c = R v^(1/3) exp(sum C[i, j, k] T_i(a) T_j(b1) T_k(b2)), a sphere of radius R "
        "and a wall with their own contact angles theta_s (the sphere's) and theta_w (the "
        "wall's), v = V/R^3; T_n Chebyshev polynomials of the first kind; each coordinate "
        "mapped to [-1, 1] as m(x; lo, hi) = (2 x - lo - hi)/(hi - lo): a = m(ln v; ln v0, "
        "ln v1), b1 = m(theta_s_deg; t0, t1), b2 from theta_w_deg within the part's range "
        "[lo, hi] of theta_w (below), [v0, v1] the domain's v, [t0, t1] its "
        "theta_sphere_deg: the table is split in the sphere's angle into bands, each with "
        "its own parts and ridge, and a point belongs to the first band whose upper "
        "theta_sphere_deg end is at or above theta_s; an end null is the onset angle "
        "theta_on(V) = sum_k o_k T_k(a) (deg, the part's theta_sphere_split, o_k its "
        "'chebyshev'; the sphere angle where the ridge's jump appears) at the point's own a, "
        "so that t0, t1 and b1's map differ from point to point"),
    "capillary-force-two-angles": (
        "F = -2 pi sigma R (cos theta_s + cos theta_w) exp(sum C[i, j, k, l] T_i(a) T_j(b1) "
        "T_k(b2) T_l(c)) for S < S_c, exactly 0 at and past S_c; c = 2 z - 1, z = sqrt(1 - "
        "ln(1 + s/eps)/ln(1 + s_c/eps)), s = S/R, s_c = S_c/R from the rupture part, eps = "
        "sqrt(v/pi); a, b1, b2 as in the rupture part (Derjaguin's force at contact times a "
        "smooth correction)"),
    "capillary-piece-two-angles": (
        "; this part covers the wall's angle theta_w from {lo} to {hi} deg (a point belongs "
        "to the first part of its band whose upper end is at or above theta_w; the domain "
        "stops at the domain's theta_wall_deg) and {b2} within it, where 'ridge' is "
        "the wall angle of the rupture distance's ridge theta_w* = sum_ij s_ij T_i(a) "
        "T_j(b1) (deg, the band's own series), where S_c peaks and the parts meet"),
    "capillary-rupture-pair-two-angles": (
        "S_c = R_s v^(1/3) exp(sum C[i, j, k, l] T_i(w) T_j(a) T_k(b1) T_l(b2)), two spheres of "
        "radii R_s <= R_l with their own contact angles theta_1 (the smaller sphere's) and "
        "theta_2 (the larger one's), v = V/R_s^3, r = R_l/R_s; T_n Chebyshev polynomials of "
        "the first kind; each coordinate mapped to [-1, 1] as m(x; lo, hi) = (2 x - lo - hi)/"
        "(hi - lo): w = m((ln r)^(1/3); 0, (ln r1)^(1/3)), a = m(ln v; ln v0, ln v1), b1 = "
        "m(theta_1_deg; t0, t1), b2 from theta_2_deg within the part's range [lo, hi] of "
        "theta_2 (below), [1, r1], [v0, v1] the domain's radius_ratio and v, [t0, t1] its "
        "theta_sphere_deg: the table is split in the small sphere's angle into bands, each "
        "with its own parts and ridge, and a point belongs to the first band whose upper "
        "theta_sphere_deg end is at or above theta_1; an end null is the onset angle "
        "theta_on(r, V) = sum_ij o_ij T_i(w) T_j(a) (deg, the part's theta_sphere_split, o_ij "
        "its 'chebyshev'; the small sphere's angle where the ridge's jump appears) at the "
        "point's own (w, a), so that t0, t1 and b1's map differ from point to point"),
    "capillary-force-pair-two-angles": (
        "F = -2 pi sigma R_s rho (cos theta_1 + cos theta_2) exp(sum C[i, j, k, l, m] T_i(w) "
        "T_j(a) T_k(b1) T_l(b2) T_m(c)) for S < S_c, exactly 0 at and past S_c; rho = R*/R_s "
        "= r/(1 + r), c = 2 z - 1, z = sqrt(1 - ln(1 + s/eps)/ln(1 + s_c/eps)), s = S/R_s, "
        "s_c = S_c/R_s from the rupture part, eps = sqrt(v/(pi rho)); w, a, b1, b2 as in the "
        "rupture part (Derjaguin's force at contact times a smooth correction)"),
    "capillary-piece-pair-two-angles": (
        "; this part covers the larger sphere's angle theta_2 from {lo} to {hi} deg (a point "
        "belongs to the first part of its band whose upper end is at or above theta_2; the "
        "domain stops at the domain's theta_large_sphere_deg) and {b2} within it, where "
        "'ridge' is the larger sphere's angle of the rupture distance's ridge theta_2* = "
        "sum_ijk s_ijk T_i(w) T_j(a) T_k(b1) (deg, the band's own series), where S_c peaks "
        "and the parts meet{past}"),
    "capillary-past-ridge": (
        ", and an upper end 'N + ridge - theta_1' is N plus the ridge's offset from the small "
        "sphere's angle, theta_2* - theta_1 (past the domain's 70 deg and the ridge)"),
    "capillary-b2-linear": "b2 = m(theta_w_deg; lo, hi)",
    "capillary-b2-quadratic": (
        "b2 quadratic toward the ridge: b2 = 1 - 2 sqrt((hi - theta_w_deg)/(hi - lo)) when "
        "the ridge is the part's upper end (hi), b2 = 2 sqrt((theta_w_deg - lo)/(hi - lo)) - "
        "1 when it is its lower end (lo), the square roots' arguments clipped at 0"),
}
ONSET_DESCRIPTION = (
    "the sphere angle theta_on (deg) where the jump of S_c at the ridge's top appears, "
    "theta_on(V) = sum_k o_k T_k(a), o_k = 'chebyshev', a = m(ln v; ln v0, ln v1): the value "
    "of each null end of this part's theta_sphere_deg, at the point's own a")
ONSET_DESCRIPTION_PAIR = (
    "the small sphere's angle theta_on (deg) where the jump of S_c at the ridge's top "
    "appears, theta_on(r, V) = sum_ij o_ij T_i(w) T_j(a), o_ij = 'chebyshev' (rows in w), w "
    "and a the ratio and volume coordinates of the form: the value of each null end of this "
    "part's theta_sphere_deg, at the point's own (w, a)")
TRAIN_NOTE = (
    "; C is the dense tensor of the piece's tensor train, the table the package evaluates "
    "(C[i_o1, ..., i_od] = G_1[:, i_o1, :] G_2[:, i_o2, :] ... G_d[:, i_od, :], Oseledets "
    "2011, over the axis order ({order}), ranks ({ranks}))")
"""Added to a capillary part's layout where its table is a tensor train's (the package
data's ``rupture_train``/``force_train``): the dense tensor written is that train's."""
LAYOUT = {"willett": "k[i, j, m] flattened in C order, shape (4, 4, 3)",
          "finite-liquid": "(p, c0, ..., c8)", "lian-rupture": "(a, b, c)"}


@cache
def schema() -> dict[str, Any]:
    """The package's JSON Schema of an exported calibration."""
    return json.loads((resources.files("wetcontact.export") / SCHEMA_FILE).read_text())


NUMBER_ARRAYS = ("coefficients", "published")
"""A part's fields that the schema declares arrays of numbers (``items: finite``): the
only large arrays of a document (calibrated-capillary's dense tensors, about 2 million
numbers, 48 MB as text)."""


def skeleton(doc: dict[str, Any]) -> dict[str, Any]:
    """``doc`` for :func:`validate`, with each part's arrays of numbers cut to one number
    once they are known to hold only numbers.

    An array of :data:`NUMBER_ARRAYS` whose elements are all exactly ``int`` or ``float``
    (JSON numbers; not ``bool``, which the schema's ``number`` refuses) is replaced by its
    first element: the schema says of such an array only that it is an array of at least
    one number, which the cut array still is. Any other value (empty, not a list, an
    element of another type) is kept whole, so the schema judges it and its error names
    the element. The same verdict as validating ``doc`` itself, in a fraction of a second
    instead of about 40 s for calibrated-capillary (jsonschema checks one number at a time
    in Python). ``doc`` is not modified: the parts are shallow copies.
    """
    parts = doc.get("parts")
    if not isinstance(parts, list):
        return doc
    cut = []
    for part in parts:
        if isinstance(part, dict):
            part = dict(part)
            for key in NUMBER_ARRAYS:
                arr = part.get(key)
                if isinstance(arr, list) and arr and set(map(type, arr)) <= {int, float}:
                    part[key] = arr[:1]
        cut.append(part)
    return {**doc, "parts": cut}


def validate(doc: dict[str, Any]) -> None:
    """Validate ``doc`` against :func:`schema` (jsonschema, when installed), its large
    arrays of numbers checked by :func:`skeleton` first.

    Raises
    ------
    jsonschema.ValidationError
        The first violation, with its path in the document.
    """
    try:
        import jsonschema
    except ImportError:  # the tests install it; a user without it still gets the file
        return
    jsonschema.validate(skeleton(doc), schema())


def _errors(summary: dict[str, Any]) -> dict[str, float]:
    return {k: float(summary[k]) for k in ("max", "mean", "p95")}


def _provenance(path: Path, generated_by: str, reference: str) -> dict[str, Any]:
    from wetcontact.store import code_version

    return {"package_version": __version__, "code_version": code_version(),
            "source_file": str(path), "source_sha256": hashlib.sha256(
                path.read_bytes()).hexdigest(), "generated_by": generated_by,
            "reference": reference,
            "exported_at": dt.datetime.now(dt.UTC).isoformat(timespec="seconds")}


def shipped_document(closure: str) -> dict[str, Any]:
    """The shipped closure ``closure`` (``calibrated-viscous`` or ``calibrated-capillary``)."""
    from wetcontact.reduced_models.calibrated import VISCOUS_FILE, viscous_table

    if closure == "calibrated-capillary":
        return capillary_document()
    if closure != "calibrated-viscous":
        raise InputError(f"--closure = {closure!r}; allowed: 'calibrated-viscous', "
                         "'calibrated-capillary' (the shipped calibrated closures; export a "
                         "refit with --coefficients FILE.json)")
    table = viscous_table()
    if table is None:
        raise InputError("calibrated-viscous: coefficient table not generated; run "
                         "`python -m wetcontact.generate calibrated-viscous`")
    parts = []
    for kind, t in table["immersed"].items():
        lo, hi = t["log_range"]
        ho = t["held_out"]
        parts.append({"name": f"immersed {kind}", "geometry": "sphere-wall" if kind ==
                      "sphere-wall" else "equal spheres", "amount": "immersed",
                      "form": FORMS["immersed"], "coefficient_layout": "Chebyshev c_0 ... c_n",
                      "coefficients": t["chebyshev"],
                      "domain": {"s_over_r": [math.exp(lo), math.exp(hi)]},
                      "held_out": {"points": ho["points"], "seed": ho["seed"],
                                   "reference": ho["reference"], "relative_error":
                                   _errors(ho)}})
    finite = [("film on a wall", "sphere-wall", "film", table["film"])] + [
        (f"bridge {kind}", kind, "bridge", t) for kind, t in table["bridge"].items()]
    for name, kind, amount, t in finite:
        ho = t["held_out"]
        corr = t.get("stokes_correction")
        form, layout, coef = FORMS["finite-liquid"], LAYOUT["finite-liquid"], t["coefficients"]
        if corr is not None:  # films: times the correction to Stokes' flat-top film
            na, nb = corr["nodes"]
            form += FORMS["film-correction"].format(d=corr["delta_over_r"],
                                                   x=corr["s_over_h"])
            layout += f", then C[i, j] flattened in C order, shape ({na}, {nb})"
            coef = list(coef) + [v for row in corr["chebyshev_2d"] for v in row]
        if amount == "bridge":
            form += FORMS["bridge-near-contact"].format(x0=t["domain"]["s_over_h"][0])
        parts.append({"name": name, "geometry": kind, "amount": amount,
                      "form": form, "coefficient_layout": layout, "coefficients": coef,
                      "domain": t["domain"],
                      "held_out": {"points": ho["points"], "seed": ho["seed"],
                                   "reference": t["reference"],
                                   "relative_error": _errors(ho["after"]),
                                   "relative_error_published": _errors(ho["before"])}})
    path = Path(str(resources.files("wetcontact.reduced_models") / "data" / VISCOUS_FILE))
    return {"format": "wetcontact-calibration", "format_version": 1, "closure": closure,
            "origin": "shipped", "target": "viscous",
            "description": "calibrated viscous closure: immersed sphere-wall and equal spheres "
                           "(Chebyshev in ln S/R), films and bridges (refitted finite-liquid "
                           "factor times the Reynolds force; films times a correction to "
                           "Stokes)",
            "units": UNITS, "sign_convention": SIGN, "outside_domain": OUTSIDE,
            "parts": parts, "provenance": _provenance(
                path, table.get("generated_by", ""), "brenner (exact) for immersed; "
                "stokes (flat film top) for films; lubrication for bridges")}


def capillary_document(table: CapillaryTable | None = None) -> dict[str, Any]:
    """The shipped ``calibrated-capillary`` closure: per generated geometry a rupture part
    and a force part, each tensor flattened in C order (its shape in the layout; where the
    piece carries tensor trains, the package evaluates them and the tensor written is the
    train's dense tensor, :attr:`~wetcontact.export.closure_tables.CapillaryPiece.force`); a wall
    with two contact angles (geometry ``sphere-wall-two-angles``) has axes (a, b1, b2) and
    a 2-D ridge series, per band of the sphere's angle (its parts' ``theta_sphere_deg``:
    the band's range, over which b1 is mapped; an end ``null`` is the onset angle, whose
    1-D series in ``a`` the part carries as ``theta_sphere_split``); two spheres with two
    contact angles (geometry ``sphere-sphere-two-angles``) likewise with axes (w, a, b1,
    b2), a 3-D ridge series, a 2-D onset series over (w, a) and the domain's
    ``theta_large_sphere_deg`` where the wall's has ``theta_wall_deg``.

    ``table``: the capillary table to write (default the shipped one,
    :func:`~wetcontact.export.closures.shipped_capillary`)."""
    from wetcontact.export.closure_tables import KINDS
    from wetcontact.export.closures import shipped_capillary

    t = shipped_capillary() if table is None else table
    parts = []
    for kind, part in t.parts.items():
        ho = part.held_out
        if not all(isinstance(ho.get(k), dict) for k in ("force", "rupture_distance")):
            raise InputError(f"{t.source}: {kind} has no held-out table; allowed: a table "
                             "written by `python -m wetcontact.generate calibrated-capillary`")
        two = part.two_angles
        axes = ("(w, a, b1, b2)" if two and part.pair else "(a, b1, b2)" if two
                else "(w, a, b)" if part.pair else "(a, b)")
        angle = ("theta_large_sphere_deg" if two and part.pair else "theta_wall_deg" if two
                 else "theta_deg")
        for sec in part.sections:
            domain = {"v": list(t.v_range)}
            if part.pair:
                domain["radius_ratio"] = list(t.ratio_range)
            band = ""
            if two:  # an end None (JSON null): the onset angle, its series in the part
                domain["theta_sphere_deg"] = [sec.theta_sphere_lo, sec.theta_sphere_hi]
                band = (f"sphere angle {sphere_end_text(sec.theta_sphere_lo)} to "
                        f"{sphere_end_text(sec.theta_sphere_hi)} deg")
            for piece in sec.pieces:
                parts.extend(_capillary_piece_parts(t, kind, part, sec, piece, axes, angle,
                                                    domain, band))
    from wetcontact.reduced_models.calibrated_capillary import capillary_table

    return {"format": "wetcontact-calibration", "format_version": 1,
            "closure": "calibrated-capillary", "origin": "shipped", "target": "capillary",
            "description": "calibrated capillary closure: tensor Chebyshev interpolants of the "
                           "meniscus solver's rupture distance and force of a pendular "
                           "bridge, sphere-wall and two spheres (radius ratio 1-10) with one "
                           "contact angle on both solids, sphere-wall-two-angles (a "
                           "sphere and a wall with their own contact angles) and "
                           "sphere-sphere-two-angles (two spheres with theirs), any gap (0 "
                           "at and past rupture)"
                           + "".join(f"; {k}: not generated" for k in KINDS
                                     if k not in t.parts),
            "units": UNITS, "sign_convention": SIGN, "outside_domain": OUTSIDE,
            "parts": parts, "transfer_fraction": _transfer_fraction(),
            "dynamic_rupture": _dynamic_rupture(),
            "provenance": _provenance(
                Path(t.source), str((capillary_table() or {}).get("generated_by", "")),
                "meniscus")}


def _transfer_fraction() -> dict[str, Any]:
    """The division at rupture (its own module, :mod:`wetcontact.export.transfer_fraction`)."""
    from wetcontact.export.transfer_fraction import json_entry

    return json_entry()


def _dynamic_rupture() -> dict[str, Any]:
    """The dynamic rupture distance (its own module, :mod:`wetcontact.export.dynamic_rupture`)."""
    from wetcontact.export.dynamic_rupture import json_entry

    return json_entry()


def _capillary_piece_parts(t: CapillaryTable, kind: str, part: CapillaryPart,
                           sec: CapillaryBand | CapillaryPart, piece: CapillaryPiece,
                           axes: str, angle: str, domain: dict[str, Any], band: str
                           ) -> list[dict[str, Any]]:
    """The rupture and force parts of one piece of one table (``sec``: the geometry, or a
    band of a wall with two angles, named by ``band``)."""
    ho = part.held_out
    two = part.two_angles
    pair2 = two and part.pair
    out = []
    split_name = "ridge" if two else "split"
    ends = [split_name if e is None else f"{e:g}" for e in (piece.theta_lo, piece.theta_hi)]
    if piece.upper_past_ridge:
        ends[1] = f"{ends[1]} + ridge - theta_1"
    other = "large sphere's angle" if pair2 else "wall angle" if two else "theta"
    where = [] if len(sec.pieces) == 1 else [f"{other} {ends[0]} to {ends[1]} deg"]
    where = f" ({', '.join(([band] if band else []) + where)})" if band or where else ""
    lo = t.theta_range_deg[0] if piece.theta_lo is None else piece.theta_lo
    hi = t.theta_range_deg[1] if piece.theta_hi is None else min(
        piece.theta_hi, t.theta_range_deg[1])  # a piece may reach past the domain
    for name, form, arr, train, held, extra in (
            ("rupture distance", "capillary-rupture", piece.rupture_table,
             piece.rupture_train, "rupture_distance", {}),
            ("force", "capillary-force", piece.force, piece.force_train, "force",
             {"s_over_sc": [0.0, 1.0]})):
        shape = ", ".join(str(n) for n in arr.shape)
        layout = (f"C flattened in C order, shape ({shape}), axes "
                  + (axes if held != "force" else axes[:-1] + ", c)"))
        if train is not None:  # the table the package evaluates: its train's
            layout += TRAIN_NOTE.format(order=", ".join(map(str, train.order)),
                                        ranks=", ".join(map(str, train.ranks)))
        coef = [float(c) for c in arr.ravel()]
        suffix = "-pair-two-angles" if pair2 else "-two-angles" if two else ""
        text = FORMS[form + suffix]
        if len(sec.pieces) > 1:
            b2 = FORMS["capillary-b2-" + ("quadratic" if piece.quadratic else "linear")]
            if pair2:
                b2 = b2.replace("theta_w_deg", "theta_2_deg")
            text += FORMS["capillary-piece" + suffix].format(
                lo=ends[0], hi=ends[1], b2=b2,
                past=FORMS["capillary-past-ridge"] if piece.upper_past_ridge else "")
        if split_name in ends:  # the split (ridge) series first, then the tensor
            what = (f"first the ridge angle's Chebyshev coefficients s_ijk flattened "
                    f"in C order, shape ({', '.join(map(str, sec.split.shape))}), "
                    "axes (w, a, b1)" if pair2 else
                    f"first the ridge angle's Chebyshev coefficients s_ij flattened "
                    f"in C order, shape ({', '.join(map(str, sec.split.shape))}), "
                    "axes (a, b1)" if two else
                    f"first the split angle's {sec.split.size} Chebyshev coefficients s_k")
            layout = f"{what}, then {layout}"
            coef = [float(c) for c in sec.split.ravel()] + coef
        held_out = {"points": int(ho[held]["points"]), "seed": int(ho["seed"]),
                    "reference": str(ho["reference"]) + " (geometry as a whole)",
                    "relative_error": _errors(ho[held])}
        strata = {k: {"points": int(s[held]["points"]), "relative_error": _errors(s[held])}
                  for k, s in part.held_out_strata.items() if isinstance(s.get(held), dict)}
        if strata:
            held_out["strata"] = strata
        out.append({"name": f"{name} {kind}{where}", "geometry": kind, "amount": "bridge",
                    "form": text, "coefficient_layout": layout, "coefficients": coef,
                    "domain": {**domain, angle: [lo, hi], **extra}, "held_out": held_out})
        if None in domain.get("theta_sphere_deg", ()):
            assert part.onset is not None  # the reader refuses a null end without it
            out[-1]["theta_sphere_split"] = {
                "chebyshev": part.onset.astype(float).tolist(),
                "description": ONSET_DESCRIPTION_PAIR if pair2 else ONSET_DESCRIPTION}
    return out


def refit_document(path: Path) -> dict[str, Any]:
    """A calibration JSON written by ``wetcontact calibrate`` / ``python -m
    wetcontact.generate fit`` (validated by :func:`~wetcontact.calibrate.load_coefficients`)."""
    from wetcontact.calibrate import labelled_coefficients, load_coefficients

    closure = load_coefficients(path)  # InputError naming the file and the field if bad
    fam = closure.family
    data = json.loads(Path(path).read_text())
    ho = data.get("held_out", {})
    for key in ("before", "after"):
        if not isinstance(ho.get(key), dict) or not all(
                isinstance(ho[key].get(k), int | float) for k in ("max", "mean", "p95")):
            raise InputError(f"{path}: field 'held_out.{key}' missing or incomplete; allowed: "
                             "a file written by wetcontact calibrate (max, mean, p95)")
    form_key = next((k for k in FORMS if fam.name.startswith(k)), fam.name)
    geometry = "equal spheres" if fam.equal else fam.kind
    part = {"name": f"{fam.name} {fam.kind} {fam.amount}", "geometry": geometry,
            "amount": fam.amount, "form": FORMS.get(form_key, fam.description),
            "coefficients": [float(c) for c in closure.k],
            "published": [float(c) for c in fam.published],
            "domain": {k: [lo, hi] for k, (lo, hi) in closure.domain.items()},
            "held_out": {"points": int(ho.get("points", 0)), "reference": str(
                data.get("reference", "meniscus")),
                "relative_error": _errors(ho["after"]),
                "relative_error_published": _errors(ho["before"])}}
    if form_key in LAYOUT:
        part["coefficient_layout"] = LAYOUT[form_key]
    part.update(labelled_coefficients(fam, closure.k, fam.published))  # each named in its form
    if "seed" in ho:
        part["held_out"]["seed"] = int(ho["seed"])
    return {"format": "wetcontact-calibration", "format_version": 1, "closure": fam.name,
            "origin": "refitted", "target": fam.target,
            "description": f"{fam.description}, refitted (not a shipped closure)",
            "units": UNITS, "sign_convention": SIGN, "outside_domain": OUTSIDE,
            "parts": [part], "provenance": _provenance(
                Path(path), "python -m wetcontact.generate fit " + fam.name,
                str(data.get("reference", "meniscus")))}


def write_json(out: str | Path, closure: str | None = None,
               coefficients: Path | None = None) -> dict[str, Any]:
    """Build, validate and write the document (exactly one of ``closure``, ``coefficients``)."""
    if (closure is None) == (coefficients is None):
        raise InputError("export json: give exactly one of --closure NAME "
                         "(calibrated-viscous, calibrated-capillary) or --coefficients "
                         "FILE.json")
    # `is not None`: an empty --closure '' is a name to refuse, not a missing one
    doc = (shipped_document(closure) if closure is not None
           else refit_document(Path(coefficients)))
    validate(doc)
    text = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    atomic_write_text(out, text)
    return {"format": "json", "out": str(out), "bytes": len(text.encode()),
            "closure": doc["closure"], "origin": doc["origin"],
            "parts": [p["name"] for p in doc["parts"]]}
