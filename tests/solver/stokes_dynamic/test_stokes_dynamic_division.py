"""The liquid each side of a dynamic bridge's neck (``stokes_dynamic.division``), against
the same cut of the static meniscus computed on the meniscus solver's own dense profile."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from wetcontact.errors import SolverError
from wetcontact.solver.meniscus import Bridge, meniscus_profile, solve_volume
from wetcontact.solver.stokes_dynamic import Domain, MeshOptions, Wetting, static_profile
from wetcontact.solver.stokes_dynamic.division import wall_fraction, wall_side_volume
from wetcontact.solver.stokes_dynamic.domain import neck

TH = math.radians(30.0)
WET = Wetting(TH, TH, 1e-3, 1e-3)


@pytest.mark.parametrize("gap,volume", [(0.08, 1e-3), (0.2, 1e-2)])
def test_wall_side_volume_is_the_meniscus_cut_at_its_neck(gap, volume):
    """A static bridge meshed as the dynamic solver's domain: the liquid below its neck
    plane equals the integral of pi r(z)^2 over z < z_n on the meniscus solver's dense
    profile (trapezoids on 20 001 points) within 1e-6 relative; the whole is the volume.
    The neck heights of the two agree within 2 % of the gap (the minimum of r(z) is flat,
    so its height is ill-conditioned; the volume is cut at the domain's)."""
    dom = Domain.from_profile(gap, static_profile(gap, volume, WET), MeshOptions())
    vw, v = wall_side_volume(SimpleNamespace(domain=dom))
    br = Bridge(radius=1.0, contact_angle1=TH, contact_angle2=TH, surface_tension=1.0)
    prof = meniscus_profile(solve_volume(br, gap, volume), n=20001)
    r, z = np.asarray(prof["r"]), np.asarray(prof["z"])
    zn = neck(dom.surface_xy)[1]
    assert zn == pytest.approx(z[int(np.argmin(r))], abs=0.02 * gap)
    k = int(np.searchsorted(z, zn))
    rn = r[k - 1] + (r[k] - r[k - 1]) * (zn - z[k - 1]) / (z[k] - z[k - 1])
    zz, rr = np.append(z[:k], zn), np.append(r[:k], rn)
    ref = float(np.pi * np.sum(0.5 * (rr[1:] ** 2 + rr[:-1] ** 2) * np.diff(zz)))
    assert v == pytest.approx(volume, rel=1e-6)
    assert vw == pytest.approx(ref, rel=1e-6)
    assert 0.0 < wall_fraction(SimpleNamespace(domain=dom)) < 1.0


def test_neck_above_the_sphere_apex_is_refused():
    dom = SimpleNamespace(surface_xy=np.array([[0.2, 0.1, 0.05], [0.0, 0.5, 1.0]]), gap=0.1,
                          volume=lambda: 1e-3)
    with pytest.raises(SolverError, match="apex"):
        wall_side_volume(SimpleNamespace(domain=dom))
