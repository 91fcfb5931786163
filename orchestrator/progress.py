"""The progress bar of runs and studies."""

from __future__ import annotations

import time
from functools import cache
from typing import Any


@cache
def _bar_class() -> type:
    """tqdm's bar without its monitor thread.  Our callers update their bars themselves
    (runs every 0.2 s, studies at each sample), and a process with no thread of its own
    can fork its sweep workers (studies/jobs.py), which then start with every module
    imported instead of importing them again."""
    from tqdm import tqdm

    class _Bar(tqdm):
        monitor_interval = 0

    return _Bar


class ProgressBar:
    """A tqdm bar made only when it is to be shown: not at all when ``disable``, and after
    ``delay`` seconds for a delayed one (importing tqdm costs 0.04-0.1 s, a tenth of a short
    run).  Takes tqdm's options; ``update`` and ``close`` as tqdm's."""

    def __init__(
        self,
        total: float | None = None,
        initial: float = 0,
        delay: float = 0.0,
        disable: bool = False,
        **options: Any,
    ) -> None:
        self.n = initial
        self._options = dict(total=total, **options)
        self._disable = disable
        self._show_at = time.monotonic() + delay
        self._started = time.time()  # tqdm's clock: the bar's elapsed time counts from here
        self._bar: Any = None
        if not disable and delay <= 0.0:
            self._show()

    def _show(self) -> None:
        self._bar = _bar_class()(initial=self.n, **self._options)
        self._bar.start_t = self._started

    def update(self, n: float = 1) -> None:
        self.n += n
        if self._bar is not None:
            self._bar.update(n)
        elif not self._disable and time.monotonic() >= self._show_at:
            self._show()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
