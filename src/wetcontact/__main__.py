"""``python -m wetcontact``: the same command line as the ``wetcontact`` script."""

from wetcontact._entry import main

raise SystemExit(main())
