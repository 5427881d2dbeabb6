r"""The pinch-off of a dynamic bridge, located from the neck's own late-time law.

Near pinch-off the neck radius of a viscous thread falls linearly in time (Papageorgiou
1995, Stokes flow: the similarity solution of the slender-thread equations),

.. math::
    h_{min}(t) = 0.0709\, \frac{\sigma}{\eta}\, (t_c - t),

so a least-squares line through the last ``decades`` of neck radius a run resolved,
``h = a (t_c - t)``, gives the pinch time t_c where it reaches zero and the rupture
distance ``S(t_c)`` (the gap history extrapolated linearly from the run's last step: the
remaining time is a small fraction of a step's worth of gap). The fitted slope ``a`` is the
measured counterpart of Papageorgiou's 0.0709; ``spread`` says how far the local slopes in
the window are from one line (a law not yet reached, or a noisy neck).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wetcontact.errors import SolverError
from wetcontact.solver.stokes_dynamic.run import DynamicRun

PAPAGEORGIOU = 0.0709
"""-d h_min/dt of a viscous thread near pinch-off, units sigma/eta (Papageorgiou 1995)."""


@dataclass(frozen=True)
class Pinch:
    """Pinch-off of a run (units R, eta R/sigma).

    Attributes
    ----------
    time, gap
        Pinch time t_c and the gap there, S(t_c)/R (the rupture distance).
    slope
        -dh_min/dt of the fitted line, units sigma/eta.
    radii
        (smallest, largest) neck radius of the fit window.
    points
        Saved states in the window.
    spread
        Largest relative deviation of the step-to-step slopes in the window from ``slope``.
    """

    time: float
    gap: float
    slope: float
    radii: tuple[float, float]
    points: int
    spread: float


def locate_pinch(run: DynamicRun, decades: float = 1.0) -> Pinch:
    """Fit ``h = a (t_c - t)`` over the run's last ``decades`` of neck radius (the states
    from the last one whose radius is at most 10^decades times the final radius)."""
    if run.stopped != "neck":
        raise SolverError(f"locate_pinch: the run stopped for '{run.stopped}', not at a "
                          "thin neck")
    h, t, s = run.neck_radius, run.time, run.gap
    above = np.nonzero(h > h[-1] * 10.0**decades)[0]
    k0 = int(above[-1]) + 1 if above.size else 0
    if h.size - k0 < 4:
        raise SolverError(f"locate_pinch: {h.size - k0} states in the last {decades:g} "
                          "decades of neck radius; at least 4")
    tw, hw = t[k0:], h[k0:]
    b, a = np.polyfit(tw, hw, 1)  # h = a + b t
    slope = -b
    if slope <= 0:
        raise SolverError("locate_pinch: the neck does not thin over the fit window")
    tc = a / slope
    local = -np.diff(hw) / np.diff(tw)
    speed = (s[-1] - s[-2]) / (t[-1] - t[-2])
    return Pinch(time=float(tc), gap=float(s[-1] + speed * (tc - t[-1])), slope=float(slope),
                 radii=(float(hw.min()), float(hw.max())), points=int(hw.size),
                 spread=float(np.max(np.abs(local / slope - 1.0))))
