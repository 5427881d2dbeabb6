"""Griffe extension for the model reference: the docstrings as Markdown, with each model's source.

The package's docstrings are numpy style with Sphinx roles (``:class:`~wetcontact.x.Y```)
and ``::`` literal-block openers. mkdocstrings renders docstrings as Markdown, where
both would show literally: a role becomes inline code of its target (the last name with
``~``, the full path without), and ``::`` at the end of a line becomes ``:``.

A registered model's class states its name, source paper and validity as class
attributes (``name``, ``reference``, ``validity``), which have no docstrings of their own;
they are added under the class docstring's first paragraph, so the reference gives each
closure's equation and paper in one place.
"""

from __future__ import annotations

import ast
import re

import griffe

_ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj|const):`(~?)([^`]+)`")
_LITERAL = re.compile(r"(\S)::$", re.MULTILINE)


def _role(match: re.Match[str]) -> str:
    tilde, target = match.groups()
    return f"`{target.rsplit('.', 1)[-1] if tilde else target}`"


def _literal(obj: griffe.Object, name: str) -> str | None:
    member = obj.members.get(name)
    if member is None or getattr(member, "value", None) is None:
        return None
    try:
        value = ast.literal_eval(str(member.value))
    except (ValueError, SyntaxError):
        return None
    return value if isinstance(value, str) else None


class SphinxRolesAsCode(griffe.Extension):
    """Rewrite each object's docstring once it is loaded."""

    def on_object(self, *, obj: griffe.Object, **kwargs) -> None:
        if obj.docstring is None:
            return
        text = _LITERAL.sub(r"\1:", _ROLE.sub(_role, obj.docstring.value))
        if obj.is_class:
            name, source = _literal(obj, "name"), _literal(obj, "reference")
            if name and source:
                lines = [f"**Model** `{name}`"
                         + (f" ({c})" if (c := _literal(obj, "component")) else "") + ".",
                         f"**Source**: {source}."]
                if validity := _literal(obj, "validity"):
                    lines.append(f"**Validity**: {validity}.")
                summary, sep, rest = text.partition("\n\n")
                text = summary + "\n\n" + "  \n".join(lines) + (sep + rest if sep else "")
        obj.docstring.value = text
