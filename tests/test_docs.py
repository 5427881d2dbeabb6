"""The user's guide: the gallery's examples run, the README's Python example runs, the
guide builds with warnings as errors, and the pages stay in step with the code and with
the project's physics notes."""

from __future__ import annotations

import ast
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((REPO / "docs" / "examples").glob("*.py"))
OUTPUT = re.compile(r"``([\w.-]+\.(?:png|json|csv|h|txt))``")
GUIDE_PACKAGES = ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")


def _env() -> dict[str, str]:
    # NO_MKDOCS_2_WARNING: mkdocs-material's banner about MkDocs 2, noise in a test's output
    return {**os.environ, "MPLBACKEND": "Agg", "NO_MKDOCS_2_WARNING": "1"}


def _outputs(example: Path) -> list[str]:
    """The files an example's docstring says it writes (``name.ext``)."""
    doc = ast.get_docstring(ast.parse(example.read_text())) or ""
    return sorted(set(OUTPUT.findall(doc)))


def test_gallery_has_examples_with_titles_and_outputs():
    assert len(EXAMPLES) >= 3
    for example in EXAMPLES:
        doc = ast.get_docstring(ast.parse(example.read_text()))
        assert doc and doc.splitlines()[0].strip(), f"{example.name}: no docstring title"
        assert _outputs(example), f"{example.name}: its docstring names no output file"


@pytest.mark.parametrize("example", EXAMPLES, ids=[e.stem for e in EXAMPLES])
def test_gallery_example_runs(example, tmp_path):
    done = subprocess.run([sys.executable, str(example)], cwd=tmp_path, env=_env(),
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    for name in _outputs(example):
        out = tmp_path / name
        assert out.is_file() and out.stat().st_size > 0, f"{example.name} did not write {name}"


def _python_blocks(markdown: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", markdown, flags=re.MULTILINE | re.DOTALL)


def test_readme_python_example_runs():
    """The README's Python example, as a user would paste it, from the repository root."""
    blocks = _python_blocks((REPO / "README.md").read_text())
    assert blocks, "README.md has no Python example"
    for code in blocks:
        assert len(code.strip().splitlines()) <= 5, "the README's example is five lines"
        done = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=_env(),
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr[-3000:]
        assert "F = -" in done.stdout  # a bridge attracts: negative by the sign convention


def test_readme_is_a_front_page():
    lines = (REPO / "README.md").read_text().splitlines()
    assert len(lines) <= 200
    text = "\n".join(lines)
    # the two set-up commands, the second the test command .ci/run runs
    assert '.venv/bin/pip install -e ".[test]" && .venv/bin/wetcontact run' in text
    assert ".venv/bin/python -m pytest -q" in text
    assert ".venv/bin/python -m pytest -q" in (REPO / ".ci" / "run").read_text()


def test_model_tables_list_every_registered_model():
    from wetcontact.models import load_all

    for page in ("README.md", "docs/reference/index.md"):
        text = (REPO / page).read_text()
        missing = [name for name in load_all() if f"| `{name}` |" not in text]
        assert not missing, f"{page}'s model table lacks {missing}"


def test_physics_notes_are_the_shared_ones():
    """docs/physics.md is ../shared/PHYSICS.md with a note under its title."""
    shared = REPO.parent / "shared" / "PHYSICS.md"
    if not shared.is_file():
        pytest.skip(f"{shared} is not beside the repository: nothing to compare the copy with")
    copy = (REPO / "docs" / "physics.md").read_text()
    note = re.search(r'\n!!! note "About this page"\n(?:    .*\n)+', copy)
    assert note, "docs/physics.md lacks its note"
    assert copy[:note.start()] + copy[note.end():] == shared.read_text(), (
        "docs/physics.md differs from ../shared/PHYSICS.md: copy the shared file again")


@pytest.mark.skipif(
    any(importlib.util.find_spec(p.split(".")[0]) is None for p in GUIDE_PACKAGES),
    reason="the guide's packages are not installed (mkdocs, mkdocs-material, "
           "mkdocstrings[python]): pip install -e '.[docs]' to build it",
)
def test_guide_builds_with_warnings_as_errors(tmp_path):
    site = tmp_path / "site"
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
         str(REPO / "mkdocs.yml"), "--site-dir", str(site)],
        cwd=REPO, env=_env(), capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-5000:]
    assert "WARNING" not in done.stderr, done.stderr[-5000:]
    gallery = (site / "gallery" / "index.html").read_text()
    for example in EXAMPLES:
        for name in _outputs(example):
            assert (site / "examples" / example.stem / name).is_file(), name
            assert f"examples/{example.stem}/{name}" in gallery, name
    reference = (site / "reference" / "viscous" / "index.html").read_text()
    assert "Adams &amp; Perchard (1985)" in reference  # a model's source, from the code
