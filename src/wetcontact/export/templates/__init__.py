"""The exports' file templates, package data beside this module, and their one renderer.

A template is the file it writes, with placeholders ``@name@`` or ``@name:spec@`` (``spec``
a :func:`format` specification, e.g. ``@s_lo:.6g@``); :func:`render` replaces each by
``format(values[name], spec)``. ``@`` appears in neither C nor the header's comments, so
the template keeps C's braces as they are (no ``{{`` escapes). A bare ``@x@`` of a float
writes its shortest round-trip repr (``format(x, "")`` is ``repr(x)`` for a float).
Substituted text is not scanned again.
"""

from __future__ import annotations

import re
from importlib import resources
from typing import Any

PLACEHOLDER = re.compile(r"@([a-z_][a-z0-9_]*)(?::([^@\n]*))?@")
"""``@name@`` or ``@name:spec@``."""


def template_text(name: str) -> str:
    """The template file ``name`` of this package (package data)."""
    return (resources.files(__name__) / name).read_text(encoding="utf-8")


def render(name: str, values: dict[str, Any]) -> str:
    """The template ``name`` with each placeholder replaced by its formatted value; a
    :class:`KeyError` naming a placeholder without a value."""
    def fill(m: re.Match[str]) -> str:
        if m[1] not in values:
            raise KeyError(f"template {name}: no value for placeholder @{m[1]}@")
        return format(values[m[1]], m[2] or "")

    return PLACEHOLDER.sub(fill, template_text(name))
