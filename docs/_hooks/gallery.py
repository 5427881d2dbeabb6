"""MkDocs hook: run the gallery's examples and put what they produce into the guide.

Each ``docs/examples/*.py`` runs in a fresh temporary folder (its working directory) with
this Python; a non-zero exit fails the build with the example's stderr. The files it
writes there (figures, JSON, CSV) are added to the site under ``examples/``, and the
marker ``<!-- gallery -->`` in ``gallery.md`` is replaced by one section per example:
its docstring, run time, figures, printed output and code.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

MARKER = "<!-- gallery -->"
TIMEOUT_S = 120


@dataclass
class Example:
    path: Path
    title: str
    description: str
    seconds: float = 0.0
    stdout: str = ""
    outputs: list[str] = field(default_factory=list)


_examples: list[Example] = []


def _docstring(path: Path) -> tuple[str, str]:
    doc = ast.get_docstring(ast.parse(path.read_text()))
    if not doc:
        raise PluginError(f"gallery: {path} has no docstring (its first line is the title)")
    title, _, rest = doc.partition("\n")
    return title.strip().rstrip("."), rest.strip()


def _run(example: Example, config) -> list[File]:
    files = []
    with tempfile.TemporaryDirectory(prefix="wetcontact-gallery-") as tmp:
        env = {**os.environ, "MPLBACKEND": "Agg"}
        start = time.perf_counter()
        try:
            done = subprocess.run([sys.executable, str(example.path)], cwd=tmp, env=env,
                                  capture_output=True, text=True, timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired as exc:
            raise PluginError(f"gallery: {example.path.name} ran past {TIMEOUT_S} s") from exc
        example.seconds = time.perf_counter() - start
        if done.returncode != 0:
            raise PluginError(f"gallery: {example.path.name} exited {done.returncode}:\n"
                              f"{done.stderr[-3000:]}")
        example.stdout = done.stdout.rstrip()
        for out in sorted(Path(tmp).iterdir()):
            if out.is_file():
                uri = f"examples/{example.path.stem}/{out.name}"
                files.append(File.generated(config, uri, content=out.read_bytes()))
                example.outputs.append(out.name)
    return files


def on_files(files, config):
    _examples.clear()
    folder = Path(config["docs_dir"]) / "examples"
    for path in sorted(folder.glob("*.py")):
        title, description = _docstring(path)
        example = Example(path, title, description)
        for generated in _run(example, config):
            files.append(generated)
        _examples.append(example)
    return files


def _section(ex: Example) -> str:
    name = ex.path.name
    parts = [f"## {ex.title}", "", ex.description, "",
             f"[`{name}`](examples/{name}) ran in {ex.seconds:.1f} s when this page was "
             f"built; it wrote {', '.join(f'`{o}`' for o in ex.outputs) or 'nothing'}.", ""]
    for out in ex.outputs:
        uri = f"examples/{ex.path.stem}/{out}"
        if out.endswith(".png"):
            parts += [f"[![{ex.title}]({uri})]({uri})", ""]
        else:
            parts += [f"Download: [`{out}`]({uri})", ""]
    if ex.stdout:
        parts += ["What it prints:", "", "```text", ex.stdout, "```", ""]
    parts += ["??? example \"The code\"", "", "    ```python"]
    parts += [("    " + line) if line else "" for line in ex.path.read_text().splitlines()]
    parts += ["    ```", ""]
    return "\n".join(parts)


def on_page_markdown(markdown, page, config, files):
    if page.file.src_uri != "gallery.md":
        return markdown
    if MARKER not in markdown:
        raise PluginError(f"gallery: gallery.md lacks the marker {MARKER}")
    return markdown.replace(MARKER, "\n".join(_section(ex) for ex in _examples))
