"""The ``wetcontact`` console script and ``python -m wetcontact``.

The command line's modules take a few tenths of a second to import; a Ctrl-C meanwhile
is answered with one line and exit code 130 (as :func:`wetcontact.cli.main` answers it
later), not an interpreter traceback; a Ctrl-C that lands in a finalizer is raised again
in the main thread rather than printed and lost (:func:`_keep_ctrl_c`).
"""

import sys
from collections.abc import Callable
from typing import Any


def _keep_ctrl_c(default: Callable[[Any], None]) -> Callable[[Any], None]:
    """An unraisable-exception hook that re-delivers a KeyboardInterrupt.

    A Ctrl-C that lands while Python runs a finalizer (a weakref callback, ``__del__``)
    cannot leave it: Python prints it as "Exception ignored ... KeyboardInterrupt" and
    the interrupt is lost. This hook raises it again in the main thread instead
    (``_thread.interrupt_main``), where the command line answers it in one line.
    """
    def hook(args: Any) -> None:
        if args.exc_type is not None and issubclass(args.exc_type, KeyboardInterrupt):
            import _thread

            _thread.interrupt_main()
            return
        default(args)

    return hook


def main() -> int:
    """Import the command line and run it; exit code 130 on a Ctrl-C while importing."""
    sys.unraisablehook = _keep_ctrl_c(sys.unraisablehook)
    try:
        from wetcontact.cli import main as cli_main
    except KeyboardInterrupt:
        sys.stderr.write("wetcontact: interrupted before any work\n")
        return 130
    return cli_main()
