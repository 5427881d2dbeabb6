"""The dynamic rupture closure in the exports: ``wc_dynamic_rupture_ratio`` in the C header,
``dynamic_rupture_ratio`` in the numpy module, its coefficients and domain in the JSON.

The closure is :func:`wetcontact.reduced_models.dynamic_rupture.dynamic_rupture_ratio`
(form, reference, accuracy in its module): ``S_c(Ca)/S_c``, the rupture distance of a bridge
separated at the capillary number Ca over its static fold. The numpy module carries the
package's :func:`~wetcontact.reduced_models.dynamic_rupture.ratio_form` verbatim; the C
function the same arithmetic. Both answer NaN outside the fitted domain.
"""

from __future__ import annotations

import inspect
import textwrap
from typing import Any

from wetcontact.reduced_models import dynamic_rupture as dr

FUNCTION = "wc_dynamic_rupture_ratio"
FORM = ("S_c(Ca)/S_c = 1 + a Ca^(b + c ln Ca) (V* / 1e-3)^d exp(e theta) rho^g, theta in rad; "
        "(a, b, c, d, e, g) per geometry (wall: a sphere and a wall, V* = V/R^3, rho = 1; "
        "pair: spheres R and R2, V* = V/R*^3 with R* = 2 R R2/(R + R2), "
        "rho = min(R, R2)/max(R, R2))")


def json_entry() -> dict[str, Any]:
    """The JSON export's entry: the form, coefficients, domain and held-out error."""
    d = dr.load()
    return {"function": FUNCTION, "schema_version": d["schema_version"],
            "quantity": "rupture distance at the capillary number Ca over the static fold",
            "form": FORM, "coefficients": d["coefficients"], "domain": d["domain"],
            "start_over_static": d["start_over_static"],
            "held_out": {k: d["held_out"][k] for k in ("points", "max", "mean", "p95",
                                                        "pitois_max")}}


C_TEMPLATE = """
/* ---- {fn}: the dynamic rupture distance over the static fold (calibrated) -------------
 * double {fn}(int pair, double ca, double v_star, double theta_deg,
 *                 double radius_ratio);
 * S_c(Ca)/S_c of a bridge separated at constant relative speed v, Ca = eta v / sigma,
 * from the static meniscus at {start:g} S_c to its pinch (free-surface Stokes flow,
 * stokes-dynamic), S_c the static fold; pair = 0 a sphere and a wall, 1 two spheres;
 * v_star = V/R^3 (R the first sphere's radius); radius_ratio = R2/R of the second sphere
 * (1 on a wall); theta_deg the static contact angle on both solids. Fitted over Ca
 * {ca_lo:g}-{ca_hi:g}, V* {v_lo:g}-{v_hi:g}, rho {q_lo:g}-1, {t_lo:g}-{t_hi:g} deg on a
 * wall, {tp_lo:g}-{tp_hi:g} deg between spheres; NaN outside.
 * {form}. Held-out relative error: max {ho_max:.2g}, mean {ho_mean:.2g} ({ho_n} runs;
 * Pitois' (1 + Ca^1/2): max {ho_pit:.2g}). Form: wetcontact/reduced_models/dynamic_rupture.py. */
static const double wc__dr_coef[2][6] = {{
    {{{wall}}},
    {{{pair}}}}};

static inline double {fn}(int pair, double ca, double v_star, double theta_deg,
                          double radius_ratio)
{{
    const double *k = wc__dr_coef[pair ? 1 : 0];
    const double t_lo = pair ? {tp_lo!r} : {t_lo!r}, t_hi = pair ? {tp_hi!r} : {t_hi!r};
    double lc, rs, rho = 1.0, v = v_star;
    if (pair) {{
        if (!(radius_ratio > 0.0))
            return NAN;
        rs = 2.0 * radius_ratio / (1.0 + radius_ratio);
        v = v_star / (rs * rs * rs);
        rho = radius_ratio < 1.0 ? radius_ratio : 1.0 / radius_ratio;
    }} else if (radius_ratio != 1.0)
        return NAN;
    if (!(ca >= {ca_lo!r} && ca <= {ca_hi!r} && v >= {v_lo!r} && v <= {v_hi!r}
          && theta_deg >= t_lo && theta_deg <= t_hi && rho >= {q_lo!r}))
        return NAN;
    lc = log(ca);
    return 1.0 + k[0] * exp((k[1] + k[2] * lc) * lc + k[3] * log(v / 1e-3)
                            + k[4] * (theta_deg * (WC_PI / 180.0)) + k[5] * log(rho));
}}
"""


def _coef(c: dict[str, float]) -> str:
    return ", ".join(repr(float(c[n])) for n in dr.NAMES)


def c_text() -> str:
    """The C function and its coefficient table (needs ``<math.h>`` and ``WC_PI``)."""
    d = dr.load()
    dom, ho = d["domain"], d["held_out"]
    return C_TEMPLATE.format(
        fn=FUNCTION, start=d["start_over_static"], form=FORM,
        ca_lo=float(dom["capillary_number"][0]), ca_hi=float(dom["capillary_number"][1]),
        v_lo=float(dom["volume"][0]), v_hi=float(dom["volume"][1]),
        q_lo=float(dom["rho"][0]),
        t_lo=float(dom["theta_deg"]["wall"][0]), t_hi=float(dom["theta_deg"]["wall"][1]),
        tp_lo=float(dom["theta_deg"]["pair"][0]), tp_hi=float(dom["theta_deg"]["pair"][1]),
        ho_max=ho["max"], ho_mean=ho["mean"], ho_n=ho["points"], ho_pit=ho["pitois_max"],
        wall=_coef(d["coefficients"]["wall"]), pair=_coef(d["coefficients"]["pair"]))


def python_text() -> str:
    """Python source (numpy only) defining ``dynamic_rupture_ratio(kind, ca, v_star,
    theta_deg, radius_ratio=1.0)``: the package's form and pair coordinates verbatim, the
    coefficients; NaN outside the domain."""
    d = dr.load()
    dom, ho = d["domain"], d["held_out"]
    src = "\n\n".join(textwrap.dedent(inspect.getsource(f)) for f in (
        dr.effective_radius, dr.pair_coordinates, dr.ratio_form))
    return f'''

# ---- dynamic_rupture_ratio: the dynamic rupture distance over the static fold ----
__all__.append("dynamic_rupture_ratio")
NAMES = {dr.NAMES!r}
_DR_COEF = {d["coefficients"]!r}
_DR_DOMAIN = {dom!r}


{src}


def dynamic_rupture_ratio(kind, ca, v_star, theta_deg, radius_ratio=1.0):
    """S_c(Ca)/S_c: the rupture distance of a bridge separated at Ca = eta v / sigma over
    its static fold; kind "wall" (a sphere and a wall) or "pair" (two spheres); v_star =
    V/R^3 (R the first sphere's radius); theta_deg the static contact angle; radius_ratio
    R2/R of the second sphere (1 on a wall). {FORM}. Fitted over Ca
    {dom["capillary_number"][0]:g}-{dom["capillary_number"][1]:g}, V*
    {dom["volume"][0]:g}-{dom["volume"][1]:g}, rho {dom["rho"][0]:g}-1, angles
    {dom["theta_deg"]["wall"]} deg on a wall, {dom["theta_deg"]["pair"]} deg between
    spheres; NaN outside. Held-out relative error: max {ho["max"]:.2g}, mean
    {ho["mean"]:.2g}."""
    if kind not in ("wall", "pair"):
        raise ValueError(f"kind = {{kind!r}}; allowed: 'wall', 'pair'")
    ca, v, th, q = np.broadcast_arrays(*(np.asarray(a, dtype=float)
                                         for a in (ca, v_star, theta_deg, radius_ratio)))
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == "wall":
            rho, ok = np.ones(q.shape), q == 1.0
        else:
            v, rho = pair_coordinates(v, q)
            ok = q > 0
        out = ratio_form(_DR_COEF, kind == "wall", ca, v, th, rho)
    inside = ok & (rho >= _DR_DOMAIN["rho"][0])
    for x, name in ((ca, "capillary_number"), (v, "volume"), (th, "theta_deg")):
        lo, hi = _DR_DOMAIN[name][kind] if name == "theta_deg" else _DR_DOMAIN[name]
        inside &= (x >= lo) & (x <= hi)
    return np.where(inside, out, np.nan)[()]
'''
