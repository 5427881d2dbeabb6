"""The ``wetcontact`` console script and ``python -m wetcontact``.

The command line's modules take a few tenths of a second to import; a Ctrl-C meanwhile
is answered with one line and exit code 130 (as :func:`wetcontact.cli.main` answers it
later), not an interpreter traceback.
"""

import sys


def main() -> int:
    """Import the command line and run it; exit code 130 on a Ctrl-C while importing."""
    try:
        from wetcontact.cli import main as cli_main
    except KeyboardInterrupt:
        sys.stderr.write("wetcontact: interrupted before any work\n")
        return 130
    return cli_main()
