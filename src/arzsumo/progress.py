"""A small progress bar with ETA on stderr (no dependency), silent with ``enabled=False``."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class Progress:
    """Report ``done`` of ``total`` units; redraws at most every ``interval`` seconds.

    On a terminal the bar redraws in place; otherwise one line per tenth of the work.
    """

    def __init__(self, total: float, label: str = "", enabled: bool = True,
                 stream: TextIO | None = None, interval: float = 0.5) -> None:
        self.total, self.label, self.enabled = max(float(total), 1e-12), label, enabled
        self.stream = stream or sys.stderr
        self.interval = interval
        self.start = time.perf_counter()
        self._last = -1e9
        self._tenth = -1
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def update(self, done: float) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        frac = min(1.0, max(0.0, done / self.total))
        if self.tty:
            if now - self._last < self.interval and frac < 1.0:
                return
        elif int(frac * 10) == self._tenth:
            return
        self._last, self._tenth = now, int(frac * 10)
        elapsed = now - self.start
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        bar = "#" * int(frac * 30)
        line = (f"{self.label} [{bar:<30}] {frac:6.1%}  elapsed {elapsed:5.0f} s  "
                f"ETA {eta:5.0f} s")
        self.stream.write(("\r" + line) if self.tty else line + "\n")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()
