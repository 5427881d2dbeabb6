"""Parametrised closure forms: the published closures written with their coefficients as an
argument, so that a fit can vary them (:mod:`wetcontact.calibrate`) and a closure can evaluate
its refitted coefficients (:mod:`wetcontact.reduced_models.calibrated`'s finite-liquid factor,
:class:`wetcontact.calibrate.CalibratedClosure`).

Each form is ``form(k, x) -> value``: ``k`` the coefficients (the published ones reproduce the
package's closure), ``x`` a mapping of per-point input arrays (SI units, radians; built by
:func:`wetcontact.calibrate.scene_inputs`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from wetcontact.reduced_models import capillary as cap
from wetcontact.reduced_models import viscous as visc

Arrays = Mapping[str, np.ndarray]


def mikami_form(k: np.ndarray, x: Arrays) -> np.ndarray:
    """Mikami's attraction (N) with coefficients ``k``, ordered as ``capillary._MIKAMI_PW``
    and ``_MIKAMI_PP``. Evaluated by ``capillary._mikami`` itself: unlike the other forms
    here it is not an independent transcription of the published closure."""
    return cap._mikami(x["gap"], x["volume"], x["r_closure"], x["sigma"], x["theta"],
                       tuple(k))


WILLETT_PUBLISHED = np.zeros((4, 4, 3))
# f_i = sum_j sum_m k[i, j, m] ln(V*)^j theta^m
WILLETT_PUBLISHED[0] = [[-0.44507, 0.050832, -1.1466], [-0.1119, -0.000411, -0.1490],
                        [-0.012101, -0.0036456, -0.01255], [-0.0005, -0.0003505, -0.00029076]]
WILLETT_PUBLISHED[1, :3] = [[1.9222, -0.57473, -1.2918], [-0.0668, -0.1201, -0.22574],
                            [-0.0013375, -0.0068988, -0.01137]]
WILLETT_PUBLISHED[2] = [[1.268, -0.01396, -0.23566], [0.198, 0.092, -0.06418],
                        [0.02232, 0.02238, -0.009853], [0.0008585, 0.001318, -0.00053]]
WILLETT_PUBLISHED[3, :3] = [[-0.010703, 0.073776, -0.34742], [0.03345, 0.04543, -0.09056],
                            [0.0018574, 0.004456, -0.006257]]


def willett_form(k: np.ndarray, x: Arrays) -> np.ndarray:
    """Willett's full fit (N) with the 48 coefficients ``k`` (shape (4, 4, 3) flattened)."""
    kk = np.asarray(k).reshape(4, 4, 3)
    r, v, th = x["r_closure"], x["volume"], x["theta"]
    lv = np.log(v / r**3)
    powers_v = np.stack([np.ones_like(lv), lv, lv**2, lv**3])
    powers_t = np.stack([np.ones_like(th), th, th**2])
    f = np.einsum("ijm,j...,m...->i...", kk, powers_v, powers_t)
    splus = 0.5 * x["gap"] * np.sqrt(r / v)
    ls = np.log(np.maximum(splus, 1e-300))
    lnf = f[0] - f[1] * np.exp(np.where(splus > 0, f[2] * ls + f[3] * ls**2, -np.inf))
    return 2.0 * np.pi * r * x["sigma"] * np.exp(lnf)


BAGHERI_PUBLISHED = np.array([0.3823, 0.2586, 0.4158, 0.2835, 0.6474, -0.2087, 0.3113, 2.267,
                              -0.3319, 0.4974, 0.6717, 0.1995, 13.84, -0.3909, -12.11,
                              -0.3945, -0.007815, -0.2105, -1.426, -1.78, 0.8351, 0.6669,
                              -0.01391])


def bagheri_form(k: np.ndarray, x: Arrays) -> np.ndarray:
    """Bagheri et al. (2024) eqs. 24-30 (N) with the 23 coefficients ``k`` (in order)."""
    r, th = x["r_closure"], x["theta"]
    vs = x["volume"] / r**3
    lv = np.log(vs)
    sc = (1.0 + 0.5 * th) * (np.cbrt(vs) + 0.1 * np.cbrt(vs) ** 2)
    s = x["gap"] / (r * sc)
    f0 = 2.0 * np.pi * (1.0 - k[0] * vs ** k[1])
    a = k[2] * vs ** k[3] + k[4]
    b = k[5] * vs ** k[6] + k[7]
    ft = (1.0 - a * np.sin(th) ** b) * f0
    a_s = k[8] * vs ** k[9] + k[10] * vs ** k[11]
    b_s = k[12] * vs ** k[13] + k[14] * vs ** k[15]
    a_t = (k[16] * lv**2 + k[17] * lv + k[18]) * th**3 + (k[19] * vs ** k[20]
                                                          + k[21] * vs ** k[22]) * th + 1.0
    f = ft * (1.0 + a_s * s) / (1.0 + a_t * b_s * a_s * s + a_t * b_s * s**2)
    return f * r * x["sigma"]


def lian_form(k: np.ndarray, x: Arrays) -> np.ndarray:
    """Rupture distance (m): ``R ((a + b theta) V*^(1/3) + c V*^(2/3))``."""
    c3 = np.cbrt(x["volume"] / x["radius"] ** 3)
    return x["radius"] * ((k[0] + k[1] * x["theta"]) * c3 + k[2] * c3**2)


def finite_liquid_form(k: np.ndarray, x: Arrays) -> np.ndarray:
    """Viscous force (N): Reynolds times the finite-liquid factor

    ``(1 - x)^p [1 + d (c0 + c1 u + c2 x + c3 x u) + d^2 (c4 + c5 u + c6 x)
    + d^3 (c7 + c8 u)]``, u = sqrt(x),

    with x = S/H and d = kappa H/R*, kappa = R*^3 (1/R1^3 + 1/R2^3) (1 for a wall): the
    surfaces' departure from the parabolic gap is ``kappa H/(2 R*)`` relative to H at the
    wetted edge. Pitois et al. (2000): p = 2, c = 0. Coefficients ``k = (p, c0, ..., c8)``.
    """
    xx = np.clip(x["gap"] / x["edge_gap"], 0.0, 1.0)
    u = np.sqrt(xx)
    d = x.get("kappa", 1.0) * x["edge_gap"] / x["r_star"]
    poly = (1.0 + d * (k[1] + k[2] * u + k[3] * xx + k[4] * xx * u)
            + d**2 * (k[5] + k[6] * u + k[7] * xx) + d**3 * (k[8] + k[9] * u))
    return (visc.reynolds_force(x["viscosity"], x["r_star"], x["velocity"], x["gap"])
            * (1.0 - xx) ** k[0] * poly)


# ---- the coefficients' names and terms -----------------------------------------------------


@dataclass(frozen=True)
class FormLabels:
    """A form's formula and, per coefficient in the order of ``k``, its name and the term it
    multiplies (or ``"exponent of ..."`` for a coefficient that is a power).

    Attributes
    ----------
    formula
        The form with its coefficients named (natural logarithms, theta in radians,
        V* = V/R^3).
    terms
        ``(name, term)`` per coefficient: ``term`` is written as in ``formula``, naming the
        sub-formula it belongs to (``"theta^2 ln V* in B"``).
    """

    formula: str
    terms: tuple[tuple[str, str], ...]


MIKAMI_LABELS = FormLabels(
    "F = pi R sigma (exp(A S/R + B) + C); A = a0 V*^a1, B = (b0 ln V* + b1) theta^2 "
    "+ b2 ln V* + b3, C = c0 ln V* + c1",
    (("a0", "V*^a1 in A"), ("a1", "exponent of V* in A"), ("b0", "theta^2 ln V* in B"),
     ("b1", "theta^2 in B"), ("b2", "ln V* in B"), ("b3", "1 in B"), ("c0", "ln V* in C"),
     ("c1", "1 in C")))


def _power(symbol: str, n: int) -> str:
    """``symbol`` to the power ``n`` as the formulas write it ("" for n = 0)."""
    return "" if n == 0 else symbol if n == 1 else f"{symbol}^{n}"


def _willett_terms() -> tuple[tuple[str, str], ...]:
    """Willett's 48 ``(name, term)`` in the order of ``k[i, j, m]`` flattened in C order."""
    out = []
    for i in range(4):
        for j in range(4):
            for m in range(3):
                term = " ".join(t for t in (_power("ln", j) + (" V*" if j else ""),
                                            _power("theta", m)) if t) or "1"
                out.append((f"f{i + 1}_{j}{m}", f"{term} in f{i + 1}"))
    return tuple(out)


WILLETT_LABELS = FormLabels(
    "F = 2 pi R sigma exp(f1 - f2 exp(f3 ln S+ + f4 ln^2 S+)), S+ = (S/2) sqrt(R/V); "
    "f_i = fi_00 + fi_01 theta + fi_02 theta^2 + fi_10 ln V* + fi_11 ln V* theta + ... "
    "+ fi_32 ln^3 V* theta^2 (fi_jm multiplies ln^j V* theta^m; k[i, j, m] flattened in C "
    "order, shape (4, 4, 3))",
    _willett_terms())

BAGHERI_LABELS = FormLabels(
    "F = R sigma F_t (1 + a_s s)/(1 + a_t b_s a_s s + a_t b_s s^2), s = S/(R s_c), s_c = "
    "(1 + theta/2)(V*^(1/3) + 0.1 V*^(2/3)); F_t = (1 - a sin(theta)^b) f0, f0 = 2 pi "
    "(1 - k0 V*^k1), a = k2 V*^k3 + k4, b = k5 V*^k6 + k7, a_s = k8 V*^k9 + k10 V*^k11, "
    "b_s = k12 V*^k13 + k14 V*^k15, a_t = (k16 ln^2 V* + k17 ln V* + k18) theta^3 + (k19 "
    "V*^k20 + k21 V*^k22) theta + 1 (Bagheri, Roy & Poeschel 2024, eqs. 24-30)",
    (("k0", "-V*^k1 in f0/(2 pi)"), ("k1", "exponent of V* in f0"), ("k2", "V*^k3 in a"),
     ("k3", "exponent of V* in a"), ("k4", "1 in a"), ("k5", "V*^k6 in b"),
     ("k6", "exponent of V* in b"), ("k7", "1 in b"), ("k8", "V*^k9 in a_s"),
     ("k9", "exponent of V* in a_s (first term)"), ("k10", "V*^k11 in a_s"),
     ("k11", "exponent of V* in a_s (second term)"), ("k12", "V*^k13 in b_s"),
     ("k13", "exponent of V* in b_s (first term)"), ("k14", "V*^k15 in b_s"),
     ("k15", "exponent of V* in b_s (second term)"), ("k16", "ln^2 V* theta^3 in a_t"),
     ("k17", "ln V* theta^3 in a_t"), ("k18", "theta^3 in a_t"),
     ("k19", "V*^k20 theta in a_t"), ("k20", "exponent of V* in a_t (first theta term)"),
     ("k21", "V*^k22 theta in a_t"), ("k22", "exponent of V* in a_t (second theta term)")))

LIAN_LABELS = FormLabels(
    "S_c = R ((a + b theta) V*^(1/3) + c V*^(2/3))",
    (("a", "V*^(1/3)"), ("b", "theta V*^(1/3)"), ("c", "V*^(2/3)")))

FINITE_LIQUID_LABELS = FormLabels(
    "F = F_Reynolds (1 - x)^p [1 + d (c0 + c1 u + c2 x + c3 x u) + d^2 (c4 + c5 u + c6 x) "
    "+ d^3 (c7 + c8 u)], x = S/H, u = sqrt(x), d = kappa H/R*",
    (("p", "exponent of (1 - x)"), ("c0", "d"), ("c1", "d u"), ("c2", "d x"),
     ("c3", "d x u"), ("c4", "d^2"), ("c5", "d^2 u"), ("c6", "d^2 x"), ("c7", "d^3"),
     ("c8", "d^3 u")))
