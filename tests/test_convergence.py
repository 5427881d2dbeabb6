"""One generic test: every registered model that declares a convergence order shows it.

A model with ``order`` set implements ``convergence_data() -> (h, err)``: mesh sizes and
errors against a reference independent of the model (analytic, a published table, or a
second method). The observed order is the least-squares slope of log err against log h.
"""

from __future__ import annotations

import pytest

from wetcontact.models import load_all, observed_order

ORDERED = sorted(name for name, m in load_all().items() if m.order is not None)


@pytest.mark.parametrize("name", ORDERED)
def test_observed_order_matches_declared(name):
    model = load_all()[name]
    h, err = model.convergence_data()
    p = observed_order(h, err)
    tol = getattr(model, "order_tolerance", 0.3)
    assert abs(p - model.order) <= tol, f"{name}: observed {p:.3f}, declared {model.order}"


def test_observed_order_recovers_a_known_slope():
    import numpy as np

    h = np.array([0.1, 0.05, 0.025])
    assert observed_order(h, 3.0 * h**2) == pytest.approx(2.0, abs=1e-12)
