"""The numpy module's ``calibrated-capillary`` evaluator is the package's own code
(:func:`wetcontact.export.python_module.evaluator_source`): the kernel's and coordinates'
source after their imports, verbatim, in one self-contained file that binds each name once.
Their values against the package: ``tests/test_export_closures.py``.
"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

from wetcontact.export.closures import capillary_source, read_refit
from wetcontact.export.python_module import (
    EVALUATOR,
    check_names,
    evaluator_source,
    module_text,
)
from wetcontact.export.refits import REFIT_FORMS
from wetcontact.reduced_models.calibrated_capillary import kernel

CALIBRATION = Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "calibration"


@pytest.fixture(scope="module")
def text() -> str:
    return module_text(capillary_source())


def test_module_carries_the_kernel_verbatim(text):
    """Every function of the spliced modules appears in the written module as in the
    package, and none of the hand-written evaluator it replaced (``_cap_train``, ...)."""
    for module in EVALUATOR:
        for name, fn in inspect.getmembers(module, inspect.isfunction):
            if fn.__module__ == module.__name__:
                assert inspect.getsource(fn) in text, name
    assert "def table_star(" in text and "_cap_train" not in text
    assert inspect.getsource(kernel.table_star) in evaluator_source()[1]


def test_module_imports_numpy_and_the_standard_library_only(text):
    tree = ast.parse(text)
    roots = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import)
             for a in n.names}
    roots |= {n.module.split(".")[0] for n in ast.walk(tree)
              if isinstance(n, ast.ImportFrom) and n.module}
    assert roots <= {"__future__", "collections", "math", "numpy", "typing"}, roots
    assert isinstance(tree.body[1], ast.ImportFrom) and tree.body[1].module == "__future__"


def test_module_binds_each_name_once(text):
    """The spliced evaluator, the template and the appended functions share one namespace:
    no name is bound twice, except to the same literal (``V_RANGE``); and the check sees a
    second binding."""
    check_names(text)
    refits = [read_refit(CALIBRATION / f"{family}.json") for family in REFIT_FORMS]
    check_names(module_text(capillary_source(), refits))  # every refit family's function
    with pytest.raises(ValueError, match="'table_star' twice"):
        check_names(text + "\n\ndef table_star():\n    pass\n")
    with pytest.raises(ValueError, match="'V_RANGE' twice"):
        check_names(text + "\n\nV_RANGE = (1e-5, 0.1)\n")
