"""High-fidelity solvers, one module each; importing this package registers their models."""

import importlib
import importlib.util

for _name in ("lubrication", "stokes", "meniscus", "thinfilm", "stokes_dynamic.model"):
    if importlib.util.find_spec(f"{__name__}.{_name}") is not None:
        importlib.import_module(f"{__name__}.{_name}")
