"""wetcontact: high-fidelity reference forces for wet particle contacts.

Solvers at increasing fidelity (closures, lubrication PDE, thin-film PDE, Stokes FEM,
Young-Laplace FEM) behind one call, ``model.force(scene, gaps) -> ForceCurve``.
"""

from typing import TYPE_CHECKING

from wetcontact.errors import CaseError, InputError, SolverError, ValidityError

if TYPE_CHECKING:
    from wetcontact.models import MODELS, ForceCurve, Model, get_model, load_all
    from wetcontact.scene import Scene, load_case, scene_from_dict

__version__ = "0.1.0"

# name -> module, imported on first use: ``import wetcontact`` (and the command line, which
# installs its Ctrl-C handling first) does not wait for numpy and scipy
_LAZY = {"MODELS": "models", "ForceCurve": "models", "Model": "models",
         "get_model": "models", "load_all": "models", "Scene": "scene",
         "load_case": "scene", "scene_from_dict": "scene"}


def __getattr__(name: str) -> object:
    """The public names of :mod:`wetcontact.models` and :mod:`wetcontact.scene`, and
    ``wetcontact.collide`` (the collision package, callable as its ``collide``), each
    loaded on first use."""
    import importlib

    if name == "collide":
        return importlib.import_module("wetcontact.collide")
    if name in _LAZY:
        value = getattr(importlib.import_module(f"wetcontact.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'wetcontact' has no attribute {name!r}")


__all__ = [
    "MODELS", "CaseError", "collide", "ForceCurve", "InputError", "Model", "Scene", "SolverError",
    "ValidityError", "get_model", "load_all", "load_case", "scene_from_dict",
]
