"""Yade's liquid-control terms from the calibrated division at rupture.

Yade's liquid migration (``LiqControl``, Mani et al. 2013; compiled only with
``YADE_LIQMIGRATION``) keeps on each ``ViscElCapPhys`` bridge the volumes ``Vf1`` and
``Vf2`` that go back to body 1 and body 2 when the bridge ruptures
(``Law2_ScGeom_ViscElCapPhys_Basic``: ``Vb/2`` each when both are zero). Those two are the
only terms through which Yade takes a division. The module written here sets them, on every
active bridge, to

.. math:: V_{f1} = f\\,V_b, \\qquad V_{f2} = (1 - f)\\,V_b,

``f`` the calibrated transfer fraction
(:func:`wetcontact.reduced_models.transfer_fraction.calibrated_transfer_fraction`, its
numpy evaluation copied in) at the bodies' radii (a body that is not a sphere is a wall),
the bridge volume ``Vb`` and each body's material angle ``theta`` (deg; Yade's single
angle per material stands for the receding angle). Outside the closure's domain and in the
band at its jump the terms are left as Yade set them (``Vb/2`` each) and counted.

Use inside Yade: ``from wetcontact_liquid import apply_liquid_division`` and
``O.engines += [PyRunner(command="apply_liquid_division(O)", iterPeriod=1)]``. A Yade
built without liquid migration (the Debian package) has no ``Vf1``: the function raises
one clear error naming the missing build option.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from wetcontact.export.transfer_fraction import python_text
from wetcontact.fileio import writable_file

MODULE_NAME = "wetcontact_liquid.py"

HEAD = '''"""Liquid division at rupture for Yade's liquid migration (LiqControl), written by
`wetcontact export yade-liquid`: apply_liquid_division(O) sets Vf1 = f Vb and
Vf2 = (1 - f) Vb on every active ViscElCapPhys bridge, f the calibrated transfer
fraction (transfer_fraction below). Needs numpy and a Yade built with YADE_LIQMIGRATION."""

import math

import numpy as np

__all__ = ["apply_liquid_division"]
'''

HOOK = '''

class NoLiquidMigration(RuntimeError):
    """This Yade keeps no liquid on the bodies (built without YADE_LIQMIGRATION)."""


def _radius(body):
    shape = body.shape
    r = getattr(shape, "radius", None)
    return math.inf if r is None or type(shape).__name__ != "Sphere" else float(r)


def apply_liquid_division(O):
    """Set Vf1, Vf2 of every active liquid bridge from the transfer fraction; return
    (set, left): how many bridges were set, and how many kept Yade's Vb/2 (outside the
    closure's domain or in the band at its jump)."""
    done = left = 0
    for i in O.interactions:
        p = i.phys
        if not hasattr(p, "liqBridgeActive") or not p.liqBridgeActive or not p.Vb > 0:
            continue
        if not hasattr(p, "Vf1"):
            raise NoLiquidMigration(
                "apply_liquid_division: this Yade has no liquid migration (ViscElCapPhys "
                "has no Vf1/Vf2): rebuild Yade with -DENABLE_LIQMIGRATION=ON")
        b1, b2 = O.bodies[i.id1], O.bodies[i.id2]
        r1, r2 = _radius(b1), _radius(b2)
        if math.isinf(r1) and math.isinf(r2):
            left += 1
            continue
        f = float(transfer_fraction(r1, r2, p.Vb, float(b1.mat.theta),
                                    float(b2.mat.theta)))
        if math.isnan(f):
            left += 1
            continue
        p.Vf1, p.Vf2 = f * p.Vb, (1.0 - f) * p.Vb
        done += 1
    return done, left
'''


def module_text() -> str:
    """The module's source: the transfer fraction's numpy evaluation and the hook."""
    return HEAD + python_text() + HOOK


def write_yade_liquid(out: str | Path) -> dict[str, Any]:
    """Write the module to ``out`` (a file, or a folder: :data:`MODULE_NAME` in it); return
    ``{"out", "bytes"}``."""
    path = Path(out)
    if path.is_dir():
        path = path / MODULE_NAME
    writable_file(path, "--out", make_folders=False)
    text = module_text()
    path.write_text(text)
    return {"out": str(path), "bytes": len(text.encode())}
