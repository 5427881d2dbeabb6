"""Report sections: one module per study, each with ``section(out, quick) -> str``.

A section writes its CSV/PNG files into ``out`` and returns the Markdown that
``reports/README.md`` shows for it. ``wetcontact run`` calls every module listed here.
"""
