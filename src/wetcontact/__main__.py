"""``python -m wetcontact``: the same command line as the ``wetcontact`` script."""

from wetcontact.cli import main

raise SystemExit(main())
