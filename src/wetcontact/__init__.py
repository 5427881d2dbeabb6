"""wetcontact: high-fidelity reference forces for wet particle contacts.

Solvers at increasing fidelity (closures, lubrication PDE, thin-film PDE, Stokes FEM,
Young-Laplace FEM) behind one call, ``model.force(scene, gaps) -> ForceCurve``.
"""

from wetcontact.errors import CaseError, InputError, SolverError, ValidityError
from wetcontact.models import MODELS, ForceCurve, Model, get_model, load_all
from wetcontact.scene import Scene, load_case, scene_from_dict

__version__ = "0.1.0"
__all__ = [
    "MODELS", "CaseError", "ForceCurve", "InputError", "Model", "Scene", "SolverError",
    "ValidityError", "get_model", "load_all", "load_case", "scene_from_dict",
]
