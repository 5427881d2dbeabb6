"""MkDocs hook: a list may start right under a paragraph line, as on GitHub.

Python-Markdown needs a blank line before a list; GitHub's Markdown does not, and the
pages written for GitHub (the physics notes, copied verbatim; the records) have lists
directly under a paragraph's last line. Before each page is converted, a blank line is
put in front of such a list's first item (``- ``, ``* `` or ``1. `` at the start of a
line, outside code blocks) unless the block it follows is itself a list.
"""

from __future__ import annotations

import re

_ITEM = re.compile(r"(?:[-*]|1\.) \S")
_FENCE = re.compile(r"\s*(```|~~~)")


def gfm_lists(markdown: str) -> str:
    out: list[str] = []
    block_start = ""  # first line of the current block (after the last blank line)
    fence = False
    for line in markdown.split("\n"):
        if _FENCE.match(line):
            fence = not fence
        elif not fence and _ITEM.match(line) and out and out[-1].strip() \
                and not _ITEM.match(block_start):
            out.append("")
            block_start = line
        if not line.strip():
            block_start = ""
        elif not block_start:
            block_start = line
        out.append(line)
    return "\n".join(out)


def on_page_markdown(markdown, page, config, files):
    return gfm_lists(markdown)
