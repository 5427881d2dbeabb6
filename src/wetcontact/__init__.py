"""wetcontact: high-fidelity reference forces for wet particle contacts.

Solvers at increasing fidelity (closures, lubrication PDE, thin-film PDE, Stokes FEM,
Young-Laplace FEM) behind one call, ``model.force(scene, gaps) -> ForceCurve``.
"""

from wetcontact.errors import CaseError, InputError, SolverError, ValidityError
from wetcontact.models import MODELS, ForceCurve, Model, get_model, load_all
from wetcontact.scene import Scene, load_case, scene_from_dict

__version__ = "0.1.0"


def __getattr__(name: str) -> object:
    """``wetcontact.collide``: the collision package (callable as its ``collide``), loaded
    on first use so that the command line does not pay for it."""
    if name == "collide":
        import importlib

        return importlib.import_module("wetcontact.collide")
    raise AttributeError(f"module 'wetcontact' has no attribute {name!r}")


__all__ = [
    "MODELS", "CaseError", "collide", "ForceCurve", "InputError", "Model", "Scene", "SolverError",
    "ValidityError", "get_model", "load_all", "load_case", "scene_from_dict",
]
