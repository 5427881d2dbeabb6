"""Refitted closure families as exported functions (``export c|python --refit FILE.json``).

One function per coefficient file, named after its family (``wc_refit_<family>`` in C,
``refit_<family>`` in Python, ``-`` written ``_``), with the signature of its target:

``capillary`` (``mikami-pw``, ``mikami-pp``, ``willett``, ``bagheri``)
    ``(r1, r2, volume, gap, surface_tension, theta1_deg, theta2_deg)`` -> force (N),
    negative (an attraction).
``rupture`` (``lian-rupture``)
    ``(r1, r2, volume, theta1_deg, theta2_deg)`` -> rupture distance S_c (m).
``viscous`` (``finite-liquid``, ``finite-liquid-bridge-sw``, ``finite-liquid-bridge-ss``)
    ``(r1, r2, viscosity, volume_or_film_thickness, approach_speed, gap)`` -> force (N),
    positive resisting approach.

``r2 = inf`` is a plane, as in the rest of the header. Each function is
:meth:`wetcontact.calibrate.CalibratedClosure.force` at one gap: the inputs of
:func:`~wetcontact.calibrate.scene_inputs` (R* = r1 r2/(r1 + r2), the closure radius
``r1`` for ``mikami-pw`` and ``lian-rupture``, ``2 R*`` for the others, the cosine-mean
angle ``acos((cos theta1 + cos theta2)/2)``, the edge gap ``H = sqrt(S^2 + V/(pi R*))`` of a
bridge, the film thickness of a film), the family's form (:mod:`wetcontact.reduced_models.
forms`), its domain coordinates (:func:`~wetcontact.calibrate.domain_coords`) each tested
with the package's tolerance ``[lo (1 - 1e-9) - 1e-12, hi (1 + 1e-9)]``, and NaN where the
package refuses: outside the fitted domain, a scene :func:`wetcontact.scene.scene_from_dict`
refuses (:data:`SCENE_LIMITS`), another geometry than the family's, a non-finite value or
a value of the wrong sign (a capillary force or rupture distance <= 0, a viscous force
against the motion).

Each family's arithmetic is written once (:data:`REFIT_FORMS`, statements in a C-like
expression language) and rendered for both languages (:func:`c_function`,
:func:`python_function`); :func:`package_refit` is the package's own value, the
reference the tests hold both exports to.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from wetcontact.errors import InputError, ValidityError
from wetcontact.export.closure_tables import RefitTable
from wetcontact.export.closures import read_refit
from wetcontact.export.package_evaluation import _scene

TARGET_ARGS = {
    "capillary": ("r1", "r2", "volume", "gap", "surface_tension", "theta1_deg", "theta2_deg"),
    "rupture": ("r1", "r2", "volume", "theta1_deg", "theta2_deg"),
    "viscous": ("r1", "r2", "viscosity", "volume_or_film_thickness", "approach_speed", "gap"),
}
"""Each target's exported signature (SI units, angles in degrees)."""

SCENE_LIMITS = (
    "r1, r2 (a sphere's) in (1e-9, 10] m; volume in (1e-30, 4/3 pi r1^3] m^3; "
    "surface_tension in (1e-5, 10] N/m; viscosity in (1e-7, 1e5] Pa s; approach_speed in "
    "[-1e3, 1e3] m/s; each angle in [0, 180) deg; gap in [max(1e-12 m, 1e-9 r_small), "
    "100 r1]; a film's thickness in (max(1e-12 m, 1e-9 r1), 10 r1] and above the gap")
"""The ranges :func:`wetcontact.scene.scene_from_dict` accepts, which the exported refits
check too (NaN outside): the package refuses such a scene before its closure is asked."""

PLANE, SPHERES, EQUAL = "WC__REFIT_PLANE", "WC__REFIT_SPHERES", "WC__REFIT_EQUAL"
"""The geometries a family takes: a plane (``r2 = inf``), two spheres of any radius ratio,
or equal spheres (|r2 - r1| <= 1e-12 r1)."""

AXIS_EXPR = {"v_star": "volume / pow(rs, 3.0)", "theta_deg": "theta * (180.0 / WC_PI)",
             "s_over_sc": "gap / sc", "s_over_h": "gap / h", "delta_over_r": "h / r1",
             "radius_ratio": "ratio"}
"""Each domain axis as the functions compute it (:func:`wetcontact.calibrate.domain_coords`,
``rs`` the smaller radius, ``sc`` the family's own rupture distance, ``h`` the edge gap)."""


@dataclass(frozen=True)
class RefitForm:
    """One family's exported arithmetic.

    Attributes
    ----------
    family
        The family's name (:data:`wetcontact.calibrate.FAMILIES`).
    target
        ``capillary``, ``rupture`` or ``viscous`` (:data:`TARGET_ARGS`).
    geometry
        :data:`PLANE`, :data:`SPHERES` or :data:`EQUAL`.
    amount
        ``bridge`` or ``film`` (a viscous family's fourth argument).
    formula
        The form in words, for the header comment and the module docstring.
    steps
        ``(name, expression)`` statements after the scene's inputs (``rstar``, ``rs``,
        ``ratio``, ``kappa``, ``theta`` or ``h``) are set, ``k[i]`` the coefficients; the
        last is ``f``, the value (a positive magnitude), and ``sc`` (the family's rupture
        distance) where the domain has ``s_over_sc``. Functions ``pow``, ``cbrt``,
        ``exp``, ``log``, ``sqrt``, ``sin``, ``fmax``, ``fmin`` and the constant ``WC_PI``
        (numpy's on the Python side).
    """

    family: str
    target: str
    geometry: str
    amount: str
    formula: str
    steps: tuple[tuple[str, str], ...]

    @property
    def c_name(self) -> str:
        return "wc_refit_" + self.family.replace("-", "_")

    @property
    def py_name(self) -> str:
        return "refit_" + self.family.replace("-", "_")


REFIT_FORMS: dict[str, RefitForm] = {}
"""Family -> its exported arithmetic; the tests iterate over it (every family is in it)."""


def register(family: str, target: str, geometry: str, formula: str, amount: str = "bridge"
             ) -> Callable[[Callable[[], tuple[tuple[str, str], ...]]], None]:
    """Decorator: the decorated function returns the family's :attr:`RefitForm.steps`."""
    def put(steps: Callable[[], tuple[tuple[str, str], ...]]) -> None:
        REFIT_FORMS[family] = RefitForm(family, target, geometry, amount, formula, steps())
    return put


def _mikami(r: str, a: float, b: float, p: float) -> tuple[tuple[str, str], ...]:
    """Mikami et al. (1998): ``F = pi r sigma (exp(A S/r + B) + C)``,
    ``S_c = r (a theta + b) V*^p`` (:func:`~wetcontact.reduced_models.rupture.
    mikami_rupture_distance_pw`/``_pp``), V* = V/r^3."""
    return (("r", r), ("vs", "volume / pow(r, 3.0)"), ("lv", "log(vs)"),
            ("sc", f"r * ({a!r} * theta + {b!r}) * pow(vs, {p!r})"),
            ("a", "k[0] * pow(vs, k[1])"),
            ("b", "(k[2] * lv + k[3]) * (theta * theta) + k[4] * lv + k[5]"),
            ("c", "k[6] * lv + k[7]"),
            ("f", "WC_PI * r * surface_tension * (exp(a * gap / r + b) + c)"))


MIKAMI = ("F = -pi R sigma (exp(A S/R + B) + C), A = a0 V*^a1, B = (b0 ln V* + b1) theta^2 "
          "+ b2 ln V* + b3, C = c0 ln V* + c1, V* = V/R^3; S_c = R ({a} theta + {b}) V*^{p} "
          "(for S/S_c); R = {r}")


@register("mikami-pw", "capillary", PLANE, MIKAMI.format(a=0.22, b=0.95, p=0.32, r="r1"))
def _mikami_pw() -> tuple[tuple[str, str], ...]:
    return _mikami("r1", 0.22, 0.95, 0.32)


@register("mikami-pp", "capillary", EQUAL,
          MIKAMI.format(a=0.62, b=0.99, p=0.34, r="2 R* = 2 r1 r2/(r1 + r2)"))
def _mikami_pp() -> tuple[tuple[str, str], ...]:
    return _mikami("2.0 * rstar", 0.62, 0.99, 0.34)


def _willett_sc() -> tuple[tuple[str, str], ...]:
    """Willett et al. (2000) eq. 15 (:func:`~wetcontact.reduced_models.rupture.
    willett_rupture_distance`): ``S_c = R (1 + theta/2)(V*^(1/3) + 0.1 V*^(2/3))``."""
    return (("r", "2.0 * rstar"), ("vs", "volume / pow(r, 3.0)"), ("c3", "cbrt(vs)"),
            ("sc", "r * (1.0 + 0.5 * theta) * (c3 + 0.1 * (c3 * c3))"))


@register("willett", "capillary", EQUAL,
          "F = -2 pi R sigma exp(f1 - f2 exp(f3 ln S+ + f4 ln^2 S+)), S+ = (S/2) sqrt(R/V), "
          "f_i = sum_jm k[i][j][m] ln^j V* theta^m (Willett et al. 2000, eq. A1), V* = V/R^3, "
          "R = 2 R*; S_c = R (1 + theta/2)(V*^(1/3) + 0.1 V*^(2/3)) (eq. 15, for S/S_c)")
def _willett() -> tuple[tuple[str, str], ...]:
    pv, pt = ("1.0", "lv", "lv2", "lv3"), ("1.0", "theta", "th2")
    fs = tuple((f"f{i}", " + ".join(f"k[{(i * 4 + j) * 3 + m}] * {pv[j]} * {pt[m]}"
                                    for j in range(4) for m in range(3))) for i in range(4))
    return (*_willett_sc(), ("lv", "log(volume / pow(r, 3.0))"), ("lv2", "lv * lv"),
            ("lv3", "pow(lv, 3.0)"), ("th2", "theta * theta"), *fs,
            ("splus", "0.5 * gap * sqrt(r / volume)"), ("ls", "log(fmax(splus, 1e-300))"),
            ("f", "2.0 * WC_PI * r * surface_tension"
                  " * exp(f0 - f1 * exp(f2 * ls + f3 * (ls * ls)))"))


@register("bagheri", "capillary", EQUAL,
          "F = -R sigma F_t (1 + a_s s)/(1 + a_t b_s a_s s + a_t b_s s^2), s = S/(R s_c), "
          "s_c = (1 + theta/2)(V*^(1/3) + 0.1 V*^(2/3)), F_t = (1 - a sin(theta)^b) 2 pi "
          "(1 - k0 V*^k1), a, b, a_s, b_s, a_t in V* and theta (Bagheri, Roy & Poeschel "
          "2024, eqs. 24-30), V* = V/R^3, R = 2 R*; S_c = R s_c (for S/S_c)")
def _bagheri() -> tuple[tuple[str, str], ...]:
    return (*_willett_sc(), ("lv", "log(vs)"),
            ("s", "gap / (r * ((1.0 + 0.5 * theta) * (c3 + 0.1 * (c3 * c3))))"),
            ("f0", "2.0 * WC_PI * (1.0 - k[0] * pow(vs, k[1]))"),
            ("a", "k[2] * pow(vs, k[3]) + k[4]"), ("b", "k[5] * pow(vs, k[6]) + k[7]"),
            ("ft", "(1.0 - a * pow(sin(theta), b)) * f0"),
            ("a_s", "k[8] * pow(vs, k[9]) + k[10] * pow(vs, k[11])"),
            ("b_s", "k[12] * pow(vs, k[13]) + k[14] * pow(vs, k[15])"),
            ("a_t", "(k[16] * (lv * lv) + k[17] * lv + k[18]) * pow(theta, 3.0)"
                   " + (k[19] * pow(vs, k[20]) + k[21] * pow(vs, k[22])) * theta + 1.0"),
            ("f", "ft * (1.0 + a_s * s) / (1.0 + a_t * b_s * a_s * s + a_t * b_s * (s * s))"
                  " * r * surface_tension"))


@register("lian-rupture", "rupture", EQUAL,
          "S_c = r1 ((a + b theta) V*^(1/3) + c V*^(2/3)), V* = V/r1^3 (Lian et al. 1993)")
def _lian() -> tuple[tuple[str, str], ...]:
    return (("c3", "cbrt(volume / pow(r1, 3.0))"),
            ("f", "r1 * ((k[0] + k[1] * theta) * c3 + k[2] * (c3 * c3))"))


FINITE_LIQUID = ("F = 6 pi eta R*^2 v/S (1 - x)^p [1 + d (c0 + c1 u + c2 x + c3 x u) + d^2 (c4 "
                 "+ c5 u + c6 x) + d^3 (c7 + c8 u)], x = S/H, u = sqrt(x), d = kappa H/R*, "
                 "kappa = R*^3 (1/r1^3 + 1/r2^3) (1 on a plane), H = {h}")


def _finite_liquid() -> tuple[tuple[str, str], ...]:
    """:func:`~wetcontact.reduced_models.forms.finite_liquid_form` (the Reynolds force times
    the refitted factor; no near-contact branch: below the fitted S/H it is NaN)."""
    return (("x", "fmin(fmax(gap / h, 0.0), 1.0)"), ("u", "sqrt(x)"), ("d", "kappa * h / rstar"),
            ("poly", "1.0 + d * (k[1] + k[2] * u + k[3] * x + k[4] * x * u)"
                     " + (d * d) * (k[5] + k[6] * u + k[7] * x) + pow(d, 3.0) * (k[8] + k[9] * u)"),
            ("f", "6.0 * WC_PI * viscosity * (rstar * rstar) * approach_speed / gap"
                  " * pow(1.0 - x, k[0]) * poly"))


@register("finite-liquid", "viscous", PLANE,
          FINITE_LIQUID.format(h="the film thickness (a film on the plane)"), amount="film")
def _finite_liquid_film() -> tuple[tuple[str, str], ...]:
    return _finite_liquid()


@register("finite-liquid-bridge-sw", "viscous", PLANE,
          FINITE_LIQUID.format(h="sqrt(S^2 + V/(pi R*)) (a bridge on a plane)"))
def _finite_liquid_sw() -> tuple[tuple[str, str], ...]:
    return _finite_liquid()


@register("finite-liquid-bridge-ss", "viscous", SPHERES,
          FINITE_LIQUID.format(h="sqrt(S^2 + V/(pi R*)) (a bridge between two spheres)"))
def _finite_liquid_ss() -> tuple[tuple[str, str], ...]:
    return _finite_liquid()


# ---- reading the files ----------------------------------------------------------------------


def read_refits(paths: Iterable[Path | str]) -> tuple[RefitTable, ...]:
    """The refits of ``--refit`` files, in order; an :class:`InputError` (one line) for a
    bad file or a second file of one family (each family is one function name)."""
    out: dict[str, RefitTable] = {}
    for path in paths:
        table = read_refit(path)
        if table.family in out:
            raise InputError(f"--refit {path}: family {table.family!r} already given by "
                             f"--refit {out[table.family].source}; allowed: one file per "
                             "family (its function is named after the family)")
        out[table.family] = table
    return tuple(out.values())


def domain_text(table: RefitTable) -> str:
    """``v_star in [1e-4, 0.1], ...`` in the family's axis order (full precision)."""
    return ", ".join(f"{k} in [{lo!r}, {hi!r}]" for k, (lo, hi) in table.domain.items())


GEOMETRY_TEXT = {PLANE: "a sphere on a plane (r2 = inf)", SPHERES: "two spheres",
                 EQUAL: "equal spheres (|r2 - r1| <= 1e-12 r1)"}


def describe(table: RefitTable) -> list[str]:
    """The lines describing one exported refit (comment or docstring, no prefix)."""
    form = REFIT_FORMS[table.family]
    args = ", ".join(TARGET_ARGS[form.target])
    what = {"capillary": "force (N, < 0)", "rupture": "rupture distance (m)",
            "viscous": "force (N, > 0 on approach)"}[form.target]
    return [f"{{name}}({args}) -> {what}: REFITTED '{table.family}', not a shipped closure",
            f"  {form.formula}; theta = acos((cos theta1 + cos theta2)/2)"
            if form.target != "viscous" else f"  {form.formula}",
            f"  geometry: {GEOMETRY_TEXT[form.geometry]}"
            + (f", {form.amount}" if form.target == "viscous" else ""),
            f"  coefficients: {Path(table.source).name}, sha256 {table.sha256[:16]}; held-out "
            f"max error {table.held_out_max:.3g} ({table.held_out_points} points)",
            f"  domain (NaN outside): {domain_text(table)}"]


def comment_lines(refits: Iterable[RefitTable], lang: str) -> list[str]:
    """The header comment's (``lang="c"``) or the module docstring's (``"python"``) block on
    the exported refits, plain lines of at most 84 characters; empty without refits."""
    refits = tuple(refits)
    if not refits:
        return []
    nan = "NAN" if lang == "c" else "NaN"
    head = (f"REFITTED FAMILIES (--refit), NOT SHIPPED CALIBRATED CLOSURES: one function per "
            "coefficient file, wetcontact's CalibratedClosure.force of that file at one gap "
            "(the same inputs, form and domain test, x in [lo (1 - 1e-9) - 1e-12, hi (1 + "
            f"1e-9)]). {nan} outside the fitted domain (no extrapolation: a gap outside the "
            f"fitted S/S_c or S/H range too), where the package refuses ({SCENE_LIMITS}; "
            "another geometry than the family's), and for a non-finite value or one of the "
            "wrong sign. Domain coordinates: v_star = V/r_small^3, theta_deg the cosine-mean "
            "angle, s_over_sc = S/S_c (the family's own S_c), s_over_h = S/H, delta_over_r = "
            "H/r1, radius_ratio = r_large/r_small.")
    out = textwrap.wrap(head, 84)
    for t in refits:
        name = REFIT_FORMS[t.family].c_name if lang == "c" else REFIT_FORMS[t.family].py_name
        first, *rest = describe(t)
        for line in [first.format(name=name), *rest]:
            out += textwrap.wrap(line.replace("NaN outside", f"{nan} outside"), 84,
                                 subsequent_indent="    ", break_on_hyphens=False)
    return out


# ---- rendering --------------------------------------------------------------------------------


def _checks(table: RefitTable) -> list[str]:
    """The domain tests, ``in_domain(coord, lo, hi)`` in the family's axis order."""
    return [f"wc__in_domain({AXIS_EXPR[a]}, {lo!r}, {hi!r})"
            for a, (lo, hi) in table.domain.items()]


def _c_array(values: Iterable[float]) -> str:
    vals = [repr(float(v)) for v in values]
    rows = [", ".join(vals[i:i + 4]) for i in range(0, len(vals), 4)]
    return "{\n        " + ",\n        ".join(rows) + "}"


def c_function(table: RefitTable) -> str:
    """The C99 function of one refit (``static inline``; helpers in :data:`C_HELPERS`)."""
    form = REFIT_FORMS[table.family]
    args = TARGET_ARGS[form.target]
    names = [n for n, _ in form.steps]
    local = ["rstar", "rs", "ratio", "kappa"] + (
        ["theta"] if form.target != "viscous" else ["h"] if form.amount == "film"
        else ["h", "volume"])
    local += [n for i, n in enumerate(names) if n not in local and n not in names[:i]]
    head = f"static inline double {form.c_name}("
    lines = [_packed(head, [f"double {a}" for a in args], ")"), "{",
             f"    static const double k[{len(table.coefficients)}] = "
             f"{_c_array(table.coefficients)};",
             f"    double {', '.join(local)};"]
    pre = f"    if (!wc__refit_geometry({form.geometry}, r1, r2, &rstar, &rs, &ratio, &kappa)"
    if form.target == "viscous":
        lines += [pre, "        || !wc__refit_viscous(viscosity, approach_speed)"
                  "\n        || !wc__refit_gap(gap, r1, rs))", "        return NAN;"]
        if form.amount == "film":
            lines += ["    if (!wc__refit_film(volume_or_film_thickness, r1, gap))",
                      "        return NAN;", "    h = volume_or_film_thickness;"]
        else:
            lines += ["    volume = volume_or_film_thickness;",
                      "    if (!wc__refit_volume(volume, r1))", "        return NAN;",
                      "    h = sqrt(gap * gap + volume / (WC_PI * rstar));"]
    else:
        cond = [pre, "        || !wc__refit_volume(volume, r1)"]
        if form.target == "capillary":
            cond += ["        || !wc__refit_gap(gap, r1, rs)",
                     "        || !wc__refit_tension(surface_tension)"]
        lines += ["\n".join(cond) + ")", "        return NAN;",
                  "    theta = wc__mean_angle(theta1_deg, theta2_deg);",
                  "    if (isnan(theta))", "        return NAN;"]
    lines += [_statement(n, e, 4, "c") for n, e in form.steps]
    checks = _checks(table)
    sign = ("f * copysign(1.0, approach_speed) < 0" if form.target == "viscous" else "f <= 0")
    lines += ["    if (!(" + "\n          && ".join(checks) + "))", "        return NAN;",
              f"    if (!isfinite(f) || {sign})", "        return NAN;",
              "    return -f;" if form.target == "capillary" else "    return f;", "}"]
    return "\n".join(lines)


def _packed(head: str, items: list[str], tail: str) -> str:
    """``head`` then ``items`` separated by commas, as many on a line as fit in 88
    columns, the continuation lines aligned after ``head``, then ``tail``."""
    lines, line = [], head
    for n, item in enumerate(items):
        piece = item + ("," if n + 1 < len(items) else tail)
        if line.strip() and len(line) + len(piece) + 1 > 88 and line != head:
            lines.append(line.rstrip())
            line = " " * len(head)
        line += piece if line.endswith(("(", " " * len(head))) else " " + piece
    return "\n".join([*lines, line])


def _statement(name: str, expr: str, indent: int, lang: str) -> str:
    """``name = expr`` at ``indent``, wrapped at 88 columns (in parentheses in Python)."""
    pad = " " * indent
    if len(pad) + len(name) + len(expr) + 4 <= 88:
        return f"{pad}{name} = {expr}" + (";" if lang == "c" else "")
    if lang == "python":
        expr = f"({expr})"
    lines = textwrap.wrap(f"{name} = {expr}", 88 - indent, break_long_words=False,
                          break_on_hyphens=False, subsequent_indent=" " * (len(name) + 4))
    return "\n".join(pad + line for line in lines) + (";" if lang == "c" else "")


_NUMPY = {"pow": "np.power", "cbrt": "np.cbrt", "exp": "np.exp", "log": "np.log",
          "sqrt": "np.sqrt", "sin": "np.sin", "fmax": "np.maximum", "fmin": "np.minimum"}


def _py(expr: str) -> str:
    """An expression of :attr:`RefitForm.steps` in numpy."""
    expr = re.sub(r"\b(" + "|".join(_NUMPY) + r")\(", lambda m: _NUMPY[m.group(1)] + "(", expr)
    return expr.replace("WC_PI", "np.pi").replace("wc__in_domain", "_in_domain")


def _py_list(values: Iterable[float]) -> str:
    vals = [repr(float(v)) for v in values]
    rows = [", ".join(vals[i:i + 3]) for i in range(0, len(vals), 3)]
    return "np.array([\n    " + ",\n    ".join(rows) + "])"


def python_function(table: RefitTable) -> str:
    """The numpy function of one refit (vectorised; helpers in :data:`PY_HELPERS`)."""
    form = REFIT_FORMS[table.family]
    args = TARGET_ARGS[form.target]
    const = "_K_" + form.family.replace("-", "_").upper()
    what = {"capillary": "Capillary force (N, negative: an attraction)",
            "rupture": "Rupture distance (m)",
            "viscous": "Viscous force (N, positive resisting approach)"}[form.target]
    lines = [f"{const} = {_py_list(table.coefficients)}", "", "",
             f"def {form.py_name}({', '.join(args)}):",
             textwrap.fill(f'"""{what} of the REFITTED {form.family!r} family '
                           f"({Path(table.source).name}); NaN outside its domain "
                           '(module docstring)."""', 88, initial_indent="    ",
                           subsequent_indent="    "),
             "    args = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (",
             f"        {', '.join(args)})))", f"    {', '.join(args)} = args",
             f"    k = {const}", "    with np.errstate(all=\"ignore\"):",
             "        ok, rstar, rs, ratio, kappa = _refit_geometry("
             f"\"{form.geometry.removeprefix('WC__REFIT_').lower()}\", r1, r2)"]
    if form.target == "viscous":
        lines += ["        ok &= _refit_viscous(viscosity, approach_speed) & "
                  "_refit_gap(gap, r1, rs)"]
        if form.amount == "film":
            lines += ["        ok &= _refit_film(volume_or_film_thickness, r1, gap)",
                      "        h = volume_or_film_thickness"]
        else:
            lines += ["        volume = volume_or_film_thickness",
                      "        ok &= _refit_volume(volume, r1)",
                      "        h = np.sqrt(gap * gap + volume / (np.pi * rstar))"]
    else:
        lines += ["        ok &= _refit_volume(volume, r1)"]
        if form.target == "capillary":
            lines += ["        ok &= _refit_gap(gap, r1, rs) & _refit_tension(surface_tension)"]
        lines += ["        theta = _mean_angle(theta1_deg, theta2_deg)",
                  "        ok &= ~np.isnan(theta)"]
    lines += [_statement(n, _py(e), 8, "python") for n, e in form.steps]
    checks = [_py(c) for c in _checks(table)]
    lines += ["        ok &= " + "\n        ok &= ".join(checks)]
    sign = ("f * np.copysign(1.0, approach_speed) >= 0" if form.target == "viscous"
            else "f > 0")
    lines += [f"        ok &= np.isfinite(f) & ({sign})",
              f"    return np.where(ok, {'-f' if form.target == 'capillary' else 'f'}, "
              "np.nan)[()]"]
    return "\n".join(lines)


C_HELPERS = """
/* ---- REFITTED families (--refit): one function per coefficient file ------------------- */

#define WC__REFIT_PLANE 0   /* a sphere on a plane: r2 = INFINITY */
#define WC__REFIT_SPHERES 1 /* two spheres, any radius ratio */
#define WC__REFIT_EQUAL 2   /* equal spheres: |r2 - r1| <= 1e-12 r1 */

/* The scene's radii (wetcontact.scene: each in (1e-9, 10] m) and the family's geometry;
 * R*, the smaller radius, the radius ratio and kappa = R*^3 (1/r1^3 + 1/r2^3) (1 on a
 * plane) as wetcontact.calibrate.scene_inputs computes them. */
static inline int wc__refit_geometry(int geometry, double r1, double r2, double *rstar,
                                     double *rs, double *ratio, double *kappa)
{
    int plane = isinf(r2) && r2 > 0;
    if (!(r1 > 1e-9 && r1 <= 10.0) || plane != (geometry == WC__REFIT_PLANE))
        return 0;
    if (!plane && !(r2 > 1e-9 && r2 <= 10.0))
        return 0;
    if (geometry == WC__REFIT_EQUAL && !(fabs(r2 - r1) <= 1e-12 * r1))
        return 0;
    *rstar = plane ? r1 : r1 * r2 / (r1 + r2);
    *rs = plane ? r1 : (r2 < r1 ? r2 : r1);
    *ratio = plane ? 1.0 : (r2 < r1 ? r1 : r2) / *rs;
    *kappa = plane ? 1.0 : pow(*rstar, 3.0) * (pow(r1, -3.0) + pow(r2, -3.0));
    return 1;
}

/* The scene's gap: [max(1e-12 m, 1e-9 r_small), 100 r1] (wetcontact.scene.min_gap). */
static inline int wc__refit_gap(double gap, double r1, double rs)
{
    return gap >= fmax(1e-12, rs / 1e9) && gap <= 100.0 * r1;
}

/* A bridge's volume: (1e-30, 4/3 pi r1^3] m^3. */
static inline int wc__refit_volume(double volume, double r1)
{
    return volume > 1e-30 && volume <= 4.0 / 3.0 * WC_PI * pow(r1, 3.0);
}

/* A film's thickness: (max(1e-12 m, 1e-9 r1), 10 r1], above the gap. */
static inline int wc__refit_film(double film, double r1, double gap)
{
    return film > fmax(1e-12, r1 / 1e9) && film <= 10.0 * r1 && film > gap;
}

static inline int wc__refit_tension(double surface_tension)
{
    return surface_tension > 1e-5 && surface_tension <= 10.0;
}

static inline int wc__refit_viscous(double viscosity, double approach_speed)
{
    return viscosity > 1e-7 && viscosity <= 1e5 && approach_speed >= -1e3
           && approach_speed <= 1e3;
}
"""
"""The C helpers of the refits (written once when at least one refit is exported)."""

PY_HELPERS = '''

# ---- REFITTED families (--refit): one function per coefficient file ----------------------


def _refit_geometry(geometry, r1, r2):
    """``geometry``: "plane" (r2 = inf), "spheres" or "equal" (|r2 - r1| <= 1e-12 r1). The
    scene's radii (each in (1e-9, 10] m) and the family's geometry; R*, the smaller
    radius, the radius ratio and kappa = R*^3 (1/r1^3 + 1/r2^3) (1 on a plane)."""
    plane = np.isinf(r2) & (r2 > 0)
    ok = (r1 > 1e-9) & (r1 <= 10.0) & (plane == (geometry == "plane"))
    ok &= plane | ((r2 > 1e-9) & (r2 <= 10.0))
    if geometry == "equal":
        ok &= np.abs(r2 - r1) <= 1e-12 * r1
    rstar = np.where(plane, r1, r1 * r2 / (r1 + r2))
    rs = np.where(plane, r1, np.minimum(r1, r2))
    ratio = np.where(plane, 1.0, np.maximum(r1, r2) / rs)
    kappa = np.where(plane, 1.0, np.power(rstar, 3.0) * (np.power(r1, -3.0)
                                                          + np.power(r2, -3.0)))
    return ok, rstar, rs, ratio, kappa


def _refit_gap(gap, r1, rs):
    """The scene's gap: [max(1e-12 m, 1e-9 r_small), 100 r1]."""
    return (gap >= np.maximum(1e-12, rs / 1e9)) & (gap <= 100.0 * r1)


def _refit_volume(volume, r1):
    return (volume > 1e-30) & (volume <= 4.0 / 3.0 * np.pi * np.power(r1, 3.0))


def _refit_film(film, r1, gap):
    return (film > np.maximum(1e-12, r1 / 1e9)) & (film <= 10.0 * r1) & (film > gap)


def _refit_tension(surface_tension):
    return (surface_tension > 1e-5) & (surface_tension <= 10.0)


def _refit_viscous(viscosity, approach_speed):
    return ((viscosity > 1e-7) & (viscosity <= 1e5) & (approach_speed >= -1e3)
            & (approach_speed <= 1e3))
'''
"""The numpy helpers of the refits (written once when at least one refit is exported)."""


def c_text(refits: Iterable[RefitTable]) -> str:
    """The refits' C code (helpers and one function each), empty without refits."""
    refits = tuple(refits)
    if not refits:
        return ""
    return C_HELPERS + "".join("\n" + c_function(t) + "\n" for t in refits)


def python_text(refits: Iterable[RefitTable]) -> str:
    """The refits' numpy code (helpers and one function each), empty without refits."""
    refits = tuple(refits)
    if not refits:
        return ""
    return PY_HELPERS + "".join("\n\n" + python_function(t) + "\n" for t in refits)


# ---- the package's own value (the exports' reference) -----------------------------------------


@cache
def _closure(source: str, family: str):
    from wetcontact.calibrate import load_coefficients

    return load_coefficients(source, family)


def package_refit(table: RefitTable, *args: float) -> float:
    """:meth:`CalibratedClosure.force <wetcontact.calibrate.CalibratedClosure>` of the
    refit at one point, the exported function's arguments ``args`` (SI, degrees, ``r2 =
    inf`` a plane); NaN where the package refuses or answers NaN.

    The scene is :func:`wetcontact.export.package_evaluation._scene`'s (water-like defaults for what
    the family does not take); a rupture family is asked at the gap ``1e-3 r1``, which its
    value does not depend on.
    """
    form = REFIT_FORMS[table.family]
    a = dict(zip(TARGET_ARGS[form.target], args, strict=True))
    closure = _closure(table.source, table.family)
    try:
        if form.target == "viscous":
            amount = {"film_thickness" if form.amount == "film" else "bridge_volume":
                      a["volume_or_film_thickness"]}
            scene = _scene(a["r1"], a["r2"], a["gap"], amount, {"viscosity": a["viscosity"]},
                           a["approach_speed"])
            return float(closure.force(scene).force_viscous[0])
        liquid = {"contact_angle_sphere": a["theta1_deg"],
                  "contact_angle_sphere2": a["theta2_deg"]}
        if form.target == "rupture":
            scene = _scene(a["r1"], a["r2"], 1e-3 * a["r1"], {"bridge_volume": a["volume"]},
                           liquid)
            return float(closure.force(scene).extras["rupture_distance"][0])
        liquid["surface_tension"] = a["surface_tension"]
        scene = _scene(a["r1"], a["r2"], a["gap"], {"bridge_volume": a["volume"]}, liquid)
        return float(closure.force(scene).force_capillary[0])
    except (ValidityError, InputError):
        return math.nan
