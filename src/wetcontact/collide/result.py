"""The frozen result of one collision and its JSON and CSV forms."""

from __future__ import annotations

import csv
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.fileio import atomic_open, json_ready


@dataclass(frozen=True)
class Phase:
    """One phase of the impact: its name and its start and end times (s)."""

    name: str
    start: float
    end: float


@dataclass(frozen=True, eq=False)
class Collision:
    """Outcome of one wet impact.

    Attributes
    ----------
    case
        Scene name.
    restitution
        ``e = -v_R / v_0``, both normal speeds at the start gap; 0 where the sphere sticks.
    outcome
        ``"rebound"`` or ``"stick"``.
    contact_velocity, rebound_velocity
        Approach speed at the solid contact and separation speed at the start gap (m/s);
        None where the sphere never got there.
    phases
        The phases in order, each with its start and end time (s).
    energy
        Joules: ``impact`` (kinetic energy at the start), ``rebound`` (at the end) and the
        work of each mechanism that acted (``viscous_approach``, ``viscous_rebound``,
        ``capillary`` (the meniscus before contact), ``bridge`` (the bridge after it),
        ``contact``, ``friction``, ``tangential_viscous``, ``drag``, ``gravity``,
        ``buoyancy``); ``impact = rebound + sum of the mechanisms``.
    models
        The viscous (approach and rebound) and capillary models used (None: switched off).
    stokes_number
        ``St = m* v0 / (6 pi eta R*^2)``.
    tangential_restitution, rebound_angle
        Oblique impacts: ratio of the contact point's slip speed after and before, and the
        rebound angle from the normal (deg).
    liquid
        Bridge volume (m^3) and static rupture distance (m), where a bridge forms.
    validity
        Where the physics of this result stops, each with the model that would apply.
    settings, diagnostics, provenance
        What changes a number; what the integrator did (``energy_residual``, the force
        tables' ``interpolation_error``, steps, wall times); versions.
    trajectory
        Time series: ``time``, ``gap``, ``velocity``, ``force_viscous``,
        ``force_capillary``, ``force_contact`` (and the tangential ones when oblique).
    """

    case: str
    restitution: float
    outcome: str
    contact_velocity: float | None
    rebound_velocity: float | None
    phases: tuple[Phase, ...]
    energy: Mapping[str, float]
    models: Mapping[str, str | None]
    stokes_number: float
    tangential_restitution: float | None = None
    rebound_angle: float | None = None
    liquid: Mapping[str, float] = field(default_factory=dict)
    validity: tuple[str, ...] = ()
    settings: Mapping[str, Any] = field(default_factory=dict)
    diagnostics: Mapping[str, Any] = field(default_factory=dict)
    provenance: Mapping[str, Any] = field(default_factory=dict)
    trajectory: Mapping[str, np.ndarray] = field(default_factory=dict)

    def to_json_dict(self) -> dict[str, Any]:
        """The result as plain JSON types (no trajectory)."""
        return json_ready({
            "case": self.case, "restitution": self.restitution, "outcome": self.outcome,
            "contact_velocity": self.contact_velocity,
            "rebound_velocity": self.rebound_velocity,
            "phases": [{"name": p.name, "start": p.start, "end": p.end}
                       for p in self.phases],
            "energy": dict(self.energy), "models": dict(self.models),
            "stokes_number": self.stokes_number,
            "tangential_restitution": self.tangential_restitution,
            "rebound_angle": self.rebound_angle, "liquid": dict(self.liquid),
            "validity": list(self.validity), "settings": dict(self.settings),
            "diagnostics": dict(self.diagnostics), "provenance": dict(self.provenance)})

    def write_trajectory(self, path: str | Path) -> None:
        """Write the trajectory as CSV (SI units), atomically."""
        keys = list(self.trajectory)
        with atomic_open(path, newline="") as fh:
            w = csv.writer(fh)
            w.writerow([f"{k} ({_UNITS.get(k, '')})" for k in keys])
            for row in zip(*(self.trajectory[k] for k in keys), strict=True):
                w.writerow([repr(float(x)) for x in row])


_UNITS = {"time": "s", "gap": "m", "velocity": "m/s", "force_viscous": "N",
          "force_capillary": "N", "force_contact": "N", "tangential_velocity": "m/s",
          "spin": "rad/s"}
