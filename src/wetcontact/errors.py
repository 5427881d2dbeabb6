"""Exceptions shared by the whole package.

The CLI maps them to exit codes: :class:`InputError` (and its subclasses) to 2,
:class:`SolverError` to 1. Every message is one line a user can act on.
"""

from __future__ import annotations

MAX_SHOWN = 120


def short_repr(value: object, quote: bool = True, limit: int = MAX_SHOWN) -> str:
    """``repr(value)`` (or ``str`` with ``quote=False``) on one line, at most ``limit`` chars.

    A hostile value (a list of millions of gaps, a 5000-character name, a string with
    newlines) must not turn a one-line error into pages: long text is cut in the middle
    with the total length shown, and line breaks are escaped. A value nested too deep for
    ``repr`` (a dict of a thousand levels) is named by its type.
    """
    if isinstance(value, list | tuple | dict) and len(value) > 8:
        text = f"{type(value).__name__} of {len(value)} items"
    else:
        try:
            text = repr(value) if quote else str(value)
        except RecursionError:
            text = f"a {type(value).__name__} nested too deep to show"
    text = text.encode("unicode_escape").decode("ascii") if not text.isprintable() else text
    if len(text) > limit:
        half = (limit - 20) // 2
        n = len(value) if isinstance(value, str) else len(text)  # a string's own length
        text = f"{text[:half]}...({n} chars)...{text[-half:]}"
    return text


class InputError(ValueError):
    """Bad input: a case file, a CLI flag or a call argument outside its allowed range."""


class CaseError(InputError):
    """A case-file field is missing, unknown or outside its allowed range.

    Parameters
    ----------
    source
        The file (or ``"<dict>"`` for an in-memory case) the field came from.
    field
        Dotted field name, e.g. ``"liquid.viscosity"``.
    value
        The offending value (``None`` when the field is missing).
    allowed
        Human-readable allowed range, e.g. ``"> 0 Pa s"``.
    """

    def __init__(self, source: str, field: str, value: object, allowed: str):
        self.source, self.field, self.value, self.allowed = source, field, value, allowed
        shown = "missing" if value is None else f"= {short_repr(value)}"
        super().__init__(f"{short_repr(source, quote=False)}: {short_repr(field, quote=False)} "
                         f"{shown}; allowed: {allowed}")


class ValidityError(InputError):
    """A model was asked for a scene outside its validity range.

    The message says why and names the model that applies instead.
    """

    def __init__(self, model: str, reason: str, use_instead: str | None = None):
        self.model, self.reason, self.use_instead = model, reason, use_instead
        tail = f"; use model '{use_instead}' instead" if use_instead else ""
        super().__init__(f"model '{model}': {reason}{tail}")


class SolverError(RuntimeError):
    """A solver failed to produce a trustworthy answer (no convergence, bad mesh, ...)."""
