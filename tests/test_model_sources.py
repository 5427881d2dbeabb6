"""Every registered model names its source (``Model.source``), and ``wetcontact models``
shows it, as a listing and as one JSON object (``--json``)."""

from __future__ import annotations

import json

import pytest

from wetcontact.cli import main
from wetcontact.models import load_all


@pytest.mark.parametrize("name", sorted(load_all()))
def test_every_registered_model_has_a_source(name: str) -> None:
    model = load_all()[name]
    assert isinstance(model.source, str) and model.source.strip(), name
    assert model.source != model.validity


def test_models_lists_each_source(capsys) -> None:
    assert main(["models"]) == 0
    out = capsys.readouterr().out
    for model in load_all().values():
        assert f"source: {model.source}" in out, model.name


def test_models_json_is_one_object_with_the_metadata(capsys) -> None:
    assert main(["models", "--json"]) == 0
    out = capsys.readouterr().out
    data = json.loads(out)  # the whole output is one JSON object
    assert isinstance(data, dict) and set(data) == set(load_all())
    for name, entry in data.items():
        model = load_all()[name]
        assert entry == {"level": model.level, "component": model.component,
                         "validity": model.validity, "source": model.source,
                         "order": model.order}
    assert data["reynolds"]["source"].startswith("Adams & Perchard 1985")
    assert data["brenner"]["source"].startswith("Brenner 1961, Chem. Eng. Sci. 16, 242")
    assert data["meniscus"]["order"] == 4.0 and data["reynolds"]["order"] is None
