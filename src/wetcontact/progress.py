"""Progress of long work on stderr (never stdout, so ``--json`` stays clean).

One mechanism for every job: on a terminal, a sweep shows tqdm's bar (points done of the
total) and a single slow call a spinner line redrawn in place; anywhere else (a log, a
pipe, CI) a background :class:`Ticker` writes one plain line every few seconds. tqdm is not
used off a terminal because it redraws with carriage returns, which a log keeps as one
unreadable line, and because it writes only when the count moves, so a single point that
takes minutes would look hung.

Users: :class:`wetcontact.cli.Progress` (a slow solve), the sweep's progress
(:mod:`wetcontact.sweep`) and the report's heartbeat (:mod:`wetcontact.report`).
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from typing import TextIO


class Ticker:
    """Write ``line()`` to ``stream`` every ``every`` seconds from a daemon thread.

    Parameters
    ----------
    line
        The text to write, called on each tick (it may read state that other threads
        change); written as given, so it carries its own ``"\\n"`` or ``"\\r"``.
    every
        Seconds between ticks.
    stream
        Where to write; ``None`` is ``sys.stderr`` at each tick (so tests that replace
        ``sys.stderr`` see the lines).
    first
        Seconds before the first tick (default ``every``).
    """

    def __init__(self, line: Callable[[], str], every: float, stream: TextIO | None = None,
                 first: float | None = None) -> None:
        self.line, self.every, self.stream = line, every, stream
        self.first = every if first is None else first
        self.ticks = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def _write(self) -> None:
        out = self.stream if self.stream is not None else sys.stderr
        out.write(self.line())
        out.flush()
        self.ticks += 1

    def _loop(self) -> None:
        if self._stop.wait(self.first):
            return
        while True:
            self._write()
            if self._stop.wait(self.every):
                return

    def start(self) -> Ticker:
        """Start ticking; returns self."""
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop ticking and wait for the thread (a tick in progress finishes)."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
