"""Closed-form closures (level 0); importing this package registers their models."""

import importlib
import importlib.util
from pathlib import Path

DATA_DIR = Path(__file__).resolve().parent / "data"
"""The package data: the shipped coefficient, refit and error-bound tables."""

for _name in ("viscous", "capillary", "rupture", "calibrated", "calibrated_capillary"):
    if importlib.util.find_spec(f"{__name__}.{_name}") is not None:
        importlib.import_module(f"{__name__}.{_name}")
