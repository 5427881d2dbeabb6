"""The calibrated transfer fraction in the exports: ``wc_transfer_fraction`` in the C header,
``transfer_fraction`` in the numpy module, its tables and domain in the JSON.

One module for the three so that the C header's and the numpy module's generators each take
one call (:func:`c_text`, :func:`python_text`) and the JSON one entry (:func:`json_entry`).
The closure is :func:`wetcontact.reduced_models.transfer_fraction.calibrated_transfer_fraction`
(form, domain, band, accuracy in its module); the numpy module carries its evaluation
functions verbatim, the C function the same arithmetic (Chebyshev-Lobatto barycentric
weights, the tensor contractions, the band), NaN outside the domain and in the band.
"""

from __future__ import annotations

import inspect
import json
import textwrap
from typing import Any

import numpy as np

from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import transfer_fraction as tf

FUNCTION = "wc_transfer_fraction"


def shipped() -> dict[str, Any]:
    """The package data of the closure and its held-out table."""
    data = json.loads((DATA_DIR / tf.TRANSFER_FILE).read_text())
    rec = json.loads((DATA_DIR / tf.RECORD_FILE).read_text())
    return {**data, "held_out": {k: rec["held_out"][k] for k in
                                 ("points", "in_band", "max", "mean", "p95", "seed")}}


def domain() -> dict[str, Any]:
    """The domain, as the exports state it."""
    return {"v_star": list(tf.V_RANGE), "radius_ratio": [1.0, tf.RATIO_MAX],
            "wall": "r2 = inf (C: INFINITY)", "theta_deg": [0.0, tf.THETA_MAX]}


def json_entry() -> dict[str, Any]:
    """The JSON export's entry: tables (node values), axes, band, domain, held-out table."""
    d = shipped()
    return {"function": FUNCTION, "schema_version": d["schema_version"],
            "quantity": "fraction of a ruptured bridge's liquid that body 1 keeps",
            "domain": domain(), "band_deg": d["band_deg"], "y_range": d["y_range"],
            "axes": d["axes"], "form": "reduced_models/transfer_fraction.py",
            **{k: d[k] for k in ("jump", "theta_end", "lower", "upper")},
            "held_out": d["held_out"]}


def _c_array(values: Any) -> str:
    flat = np.asarray(values, dtype=float).ravel()
    lines = [", ".join(repr(float(v)) for v in flat[i:i + 4]) for i in range(0, flat.size, 4)]
    return "{\n    " + ",\n    ".join(lines) + "\n}"


C_TEMPLATE = """
/* ---- {fn}: the division of the liquid at rupture (calibrated) ----------------------
 * double {fn}(double r1, double r2, double volume, double theta1_deg,
 *             double theta2_deg);
 * The fraction of a ruptured bridge's liquid that body 1 keeps (body 2 keeps 1 - f), the
 * meniscus model's transfer_fraction (the critical bridge cut at its neck) calibrated over:
 * a sphere and a plane (r2 = INFINITY, or r1 = INFINITY) or two spheres of radius ratio
 * 1-{q_hi:g}, receding angles 0-{t_hi:g} deg each, V/R_small^3 in [{v_lo:g}, {v_hi:g}]; NaN
 * outside, and within {band:g} deg of the jump of the division (|theta_l - K| < d_min, the
 * smaller sphere's angle theta_s and the other's theta_l). Held-out absolute error against
 * meniscus: max {ho_max:.2g}, mean {ho_mean:.2g}, p95 {ho_p95:.2g} ({ho_n} points, {ho_band}
 * in the band). Form: wetcontact/reduced_models/transfer_fraction.py. */
#define WC__TF_NT {nt}
#define WC__TF_NY {ny}
#define WC__TF_NX {nx}
#define WC__TF_NS {ns}
#define WC__TF_NV {nv}
#define WC__TF_NXU {nxu}
#define WC__TF_NSU {nsu}
#define WC__TF_NTJ {ntj}
#define WC__TF_NYJ {nyj}
#define WC__TF_NXJ {nxj}
static const double wc__tf_jump[{n_jump}] = {jump};
static const double wc__tf_end[{n_end}] = {end};
static const double wc__tf_lower[{n_lower}] = {lower};
static const double wc__tf_upper[{n_upper}] = {upper};

/* Barycentric weights of the Chebyshev-Lobatto interpolant (nodes -cos(pi j/(n - 1))) at x. */
static inline void wc__tf_weights(double x, int n, double *w)
{{
    int j, hit = -1;
    double sum = 0.0, node;
    for (j = 0; j < n; j++) {{
        node = -cos(WC_PI * j / (n - 1));
        if (x - node == 0.0 && hit < 0)
            hit = j;
        w[j] = ((j % 2) ? -1.0 : 1.0) * ((j == 0 || j == n - 1) ? 0.5 : 1.0) / (x - node);
    }}
    if (hit >= 0) {{
        for (j = 0; j < n; j++)
            w[j] = (j == hit) ? 1.0 : 0.0;
        return;
    }}
    for (j = 0; j < n; j++)
        sum += w[j];
    for (j = 0; j < n; j++)
        w[j] /= sum;
}}

static inline double wc__tf_unit(double x, double lo, double hi)
{{
    return (2.0 * x - (lo + hi)) / (hi - lo);
}}

static inline double wc__tf_clip(double x, double lo, double hi)
{{
    return x < lo ? lo : (x > hi ? hi : x);
}}

/* s in [-1, 1], linear in d^(1/3) over [d_min^(1/3), d_max^(1/3)]. */
static inline double wc__tf_side(double d, double d_max, double d_min)
{{
    double a = pow(d_min, 1.0 / 3.0);
    double b = cbrt(d_max > d_min * (1.0 + 1e-9) ? d_max : d_min * (1.0 + 1e-9));
    return 2.0 * (cbrt(d) - a) / (b - a) - 1.0;
}}

/* sum t[i][j][k][l] w0[i] w1[j] w2[k] w3[l] (an axis of length 1 enters with weight 1:
 * n3 = 1 three axes, n2 = n3 = 1 two). */
static inline double wc__tf_tensor(const double *t, const double *w0, int n0, const double *w1,
                                   int n1, const double *w2, int n2, const double *w3, int n3)
{{
    int i, j, k, l;
    double out = 0.0, a, b, c;
    for (i = 0; i < n0; i++) {{
        a = 0.0;
        for (j = 0; j < n1; j++) {{
            b = 0.0;
            for (k = 0; k < n2; k++) {{
                c = 0.0;
                for (l = 0; l < n3; l++)
                    c += t[((i * n1 + j) * n2 + k) * n3 + l] * (n3 > 1 ? w3[l] : 1.0);
                b += c * (n2 > 1 ? w2[k] : 1.0);
            }}
            a += b * w1[j];
        }}
        out += a * w0[i];
    }}
    return out;
}}

static inline double {fn}(double r1, double r2, double volume, double theta1_deg,
                                    double theta2_deg)
{{
    const double y_lo = {y_lo!r}, y_hi = {y_hi!r}, band = {band!r};
    double rs, rl, vstar, xi, y, ts, tl, k, f, d_max, te, s;
    double wt[WC__TF_NT], wy[WC__TF_NY], wx[WC__TF_NX], ws[WC__TF_NS], wv[WC__TF_NV];
    double wxu[WC__TF_NXU], wsu[WC__TF_NSU], wtj[WC__TF_NTJ], wyj[WC__TF_NYJ];
    double wxj[WC__TF_NXJ];
    const double one[1] = {{1.0}};
    int swapped;
    if (isnan(r1) || isnan(r2) || isnan(volume) || isnan(theta1_deg) || isnan(theta2_deg))
        return NAN;
    swapped = r1 > r2 || (r1 == r2 && theta1_deg > theta2_deg);
    rs = r1 < r2 ? r1 : r2;
    rl = r1 < r2 ? r2 : r1;
    if (!(rs > 0) || !isfinite(rs) || !(rl > 0) || !(volume > 0))
        return NAN;
    if (isfinite(rl) && !(rl / rs <= {q_hi!r} * (1 + 1e-12)))
        return NAN;
    vstar = volume / (rs * rs * rs);
    if (!(vstar >= {v_lo!r} * (1 - 1e-12) && vstar <= {v_hi!r} * (1 + 1e-12)))
        return NAN;
    if (!(theta1_deg >= 0.0 && theta1_deg <= {t_hi!r} && theta2_deg >= 0.0
          && theta2_deg <= {t_hi!r}))
        return NAN;
    ts = swapped ? theta2_deg : theta1_deg;
    tl = swapped ? theta1_deg : theta2_deg;
    xi = cbrt(wc__tf_clip(1.0 - rs / rl, 0.0, 1.0));
    y = log(wc__tf_clip(vstar, {v_lo!r}, {v_hi!r}));
    if (xi == 0.0 && ts == tl)
        return 0.5;  /* equal spheres, equal angles: 1/2 by symmetry */
    wc__tf_weights(wc__tf_unit(ts, 0.0, {t_hi!r}), WC__TF_NTJ, wtj);
    wc__tf_weights(wc__tf_unit(y, y_lo, y_hi), WC__TF_NY, wy);
    wc__tf_weights(wc__tf_unit(y, y_lo, y_hi), WC__TF_NYJ, wyj);
    wc__tf_weights(2.0 * xi - 1.0, WC__TF_NXJ, wxj);
    k = wc__tf_tensor(wc__tf_jump, wtj, WC__TF_NTJ, wyj, WC__TF_NYJ, wxj, WC__TF_NXJ, one, 1);
    if (fabs(tl - k) < band)
        return NAN;  /* the band at the jump */
    if (tl < k) {{
        wc__tf_weights(wc__tf_unit(ts, 0.0, {t_hi!r}), WC__TF_NT, wt);
        wc__tf_weights(2.0 * xi - 1.0, WC__TF_NX, wx);
        s = wc__tf_side(k - tl, k, band);
        wc__tf_weights(wc__tf_clip(s, -1.0, 1.0), WC__TF_NS, ws);
        f = wc__tf_tensor(wc__tf_lower, wt, WC__TF_NT, wy, WC__TF_NY, wx, WC__TF_NX, ws,
                          WC__TF_NS);
    }} else {{
        te = wc__tf_tensor(wc__tf_end, wyj, WC__TF_NYJ, wxj, WC__TF_NXJ, one, 1, one, 1);
        d_max = band + 0.5 * (({t_hi!r} - k) + sqrt(({t_hi!r} - k) * ({t_hi!r} - k) + 4.0));
        s = wc__tf_side(tl - k, d_max, band);
        wc__tf_weights(wc__tf_clip(wc__tf_unit(ts / te, 0.0, 1.0), -1.0, 1.0), WC__TF_NV,
                       wv);
        wc__tf_weights(2.0 * xi - 1.0, WC__TF_NXU, wxu);
        wc__tf_weights(wc__tf_clip(s, -1.0, 1.0), WC__TF_NSU, wsu);
        f = wc__tf_tensor(wc__tf_upper, wv, WC__TF_NV, wy, WC__TF_NY, wxu, WC__TF_NXU, wsu,
                          WC__TF_NSU);
    }}
    return swapped ? 1.0 - f : f;
}}
"""


def c_text() -> str:
    """The C99 code of :data:`FUNCTION` (needs ``<math.h>`` and ``WC_PI``)."""
    d = shipped()
    jump, lower, upper = (np.asarray(d[k]) for k in ("jump", "lower", "upper"))
    nt, ny, nx, ns = lower.shape
    nv, nyu, nxu, nsu = upper.shape
    ntj, nyj, nxj = jump.shape
    if nyu != ny:
        raise ValueError(f"transfer fraction: upper table's y points {nyu} != lower's {ny}")
    ho = d["held_out"]
    return C_TEMPLATE.format(
        fn=FUNCTION, nt=nt, ny=ny, nx=nx, ns=ns, nv=nv, nxu=nxu, nsu=nsu, ntj=ntj, nyj=nyj,
        nxj=nxj, n_jump=jump.size, n_end=nxj * nyj, n_lower=lower.size, n_upper=upper.size,
        jump=_c_array(jump), end=_c_array(d["theta_end"]),
        lower=_c_array(lower), upper=_c_array(d["upper"]), y_lo=d["y_range"][0],
        y_hi=d["y_range"][1], band=d["band_deg"], q_hi=tf.RATIO_MAX, t_hi=tf.THETA_MAX,
        v_lo=tf.V_RANGE[0], v_hi=tf.V_RANGE[1], ho_max=ho["max"], ho_mean=ho["mean"],
        ho_p95=ho["p95"], ho_n=ho["points"], ho_band=ho["in_band"])


PY_FUNCTIONS = (tf.lobatto, tf.lobatto_basis, tf.to_unit, tf.upper_width, tf.side_coordinate,
                tf.node_weights, tf.outer_rows, tf.tensor_eval, tf.canonical, tf.evaluate)
"""The closure's evaluation, copied verbatim into the numpy module."""


def python_text() -> str:
    """Python source (numpy only) defining ``transfer_fraction(r1, r2, volume, theta1_deg,
    theta2_deg)``: the closure's evaluation functions verbatim and its tables; NaN outside
    the domain and in the band; ``r2 = inf`` (or ``None``) for a plane."""
    d = shipped()
    src = "\n\n".join(textwrap.dedent(inspect.getsource(f)) for f in PY_FUNCTIONS)
    tables = ", ".join(f'"{k}": np.array({np.asarray(d[k]).ravel().tolist()!r})'
                       f".reshape({np.asarray(d[k]).shape!r})"
                       for k in ("jump", "theta_end", "lower", "upper"))
    ho = d["held_out"]
    return f'''

# ---- transfer_fraction: the division of the liquid at rupture (calibrated) ----
from typing import Any  # noqa: E402  (the annotations of the functions below)

__all__.append("transfer_fraction")
THETA_MAX = {tf.THETA_MAX!r}
RATIO_MAX = {tf.RATIO_MAX!r}
V_RANGE = {tuple(tf.V_RANGE)!r}
LOBATTO_BASES: dict[int, tuple[np.ndarray, np.ndarray]] = {{}}  # lobatto_basis's cache
_TF_TABLES = {{"band_deg": {d["band_deg"]!r}, "y_range": {tuple(d["y_range"])!r}, {tables}}}


{src}


def transfer_fraction(r1, r2, volume, theta1_deg, theta2_deg):
    """Fraction of a ruptured bridge's liquid that body 1 keeps (body 2 keeps 1 - f): the
    meniscus transfer_fraction calibrated over a sphere and a plane (r2 = inf or None) or two
    spheres of radius ratio 1-{tf.RATIO_MAX:g}, receding angles 0-{tf.THETA_MAX:g} deg,
    V/R_small^3 in [{tf.V_RANGE[0]:g}, {tf.V_RANGE[1]:g}]; NaN outside and within
    {d["band_deg"]:g} deg of the jump of the division. Held-out absolute error: max
    {ho["max"]:.2g}, mean {ho["mean"]:.2g}, p95 {ho["p95"]:.2g} ({ho["points"]} points)."""
    r1 = np.inf if r1 is None else r1
    r2 = np.inf if r2 is None else r2
    args = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in
                                 (r1, r2, volume, theta1_deg, theta2_deg)))
    shape = args[0].shape
    y, xi, th_s, th_l, swapped, inside = canonical(*(a.ravel() for a in args))
    f = np.full(y.shape, np.nan)
    if inside.any():
        f_s, _ = evaluate(_TF_TABLES, y[inside], xi[inside], th_s[inside], th_l[inside])
        f[inside] = np.where(swapped[inside], 1.0 - f_s, f_s)
    return f.reshape(shape)[()]
'''
