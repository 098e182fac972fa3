"""Progress bars on stderr (no dependency), silent with ``enabled=False``.

:class:`Progress` counts units of equal cost (the runs of a sweep); :class:`RunProgress`
follows a run made of named phases of unequal cost (a SUMO run: warm-up, control window,
drain, outputs), its time left from :class:`PhaseClock`.
"""

from __future__ import annotations

import sys
import textwrap
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TextIO

#: a clock in seconds (``time.perf_counter``; a fake one in tests)
Clock = Callable[[], float]


def duration_text(seconds: float) -> str:
    """``42 s``, ``3 min 05 s``, ``1 h 02 min``."""
    s = max(0, round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


class Progress:
    """Report ``done`` of ``total`` units; redraws at most every ``interval`` seconds.

    On a terminal the bar redraws in place; otherwise one line per tenth of the work.
    """

    def __init__(self, total: float, label: str = "", enabled: bool = True,
                 stream: TextIO | None = None, interval: float = 0.5,
                 clock: Clock = time.perf_counter) -> None:
        self.total, self.label, self.enabled = max(float(total), 1e-12), label, enabled
        self.stream = stream or sys.stderr
        self.interval, self.clock, self.start = interval, clock, clock()
        self._last, self._tenth = -1e9, -1
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def update(self, done: float) -> None:
        if not self.enabled:
            return
        now = self.clock()
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


@dataclass(frozen=True)
class Phase:
    """One named phase of a run (``name`` shown on screen: "warm-up", "control", ...).

    ``work`` is its units (simulated s, vehicles, 1 for a single step), named ``unit`` on
    screen ("": none shown); ``cost`` its expected wall time, in a unit shared by the run's
    phases (only ratios matter); ``settle`` the fraction of it whose rate does not predict
    the rest (a SUMO network that fills from empty steps faster than a full one).
    """

    name: str
    work: float = 1.0
    cost: float = 1.0
    settle: float = 0.0
    unit: str = ""

    def __post_init__(self) -> None:
        if not self.work > 0 or not self.cost >= 0 or not 0 <= self.settle < 1:
            raise ValueError(f"phase {self.name!r}: work = {self.work} (> 0), cost = "
                             f"{self.cost} (>= 0), settle = {self.settle} (in [0, 1)) "
                             "expected")


class PhaseClock:
    """Time left in a run of :class:`Phase`\\ s, on a clock (``time.perf_counter`` or fake).

    The rest of the current phase is its work left over its own rate, measured on the
    last ``window`` seconds after the phase settled. The phases to come take their cost
    times the seconds per unit of cost last measured: on the current phase once it has a
    rate, else on the last phase that finished. Until one of them exists, nothing is
    known: :meth:`seconds_left` is None.
    """

    def __init__(self, phases: Sequence[Phase], clock: Clock = time.perf_counter,
                 window: float = 20.0) -> None:
        if not phases:
            raise ValueError("a run needs at least one phase")
        self.phases = list(phases)
        self.clock, self.window = clock, window
        self.start = clock()
        self.index = 0
        self.durations: dict[str, float] = {}
        self._entered, self._done, self._offset = self.start, 0.0, 0.0
        self._samples: deque[tuple[float, float]] = deque()
        self._per_cost: float | None = None   # seconds per unit of cost, last measured
        self._settled_at: tuple[float, float] | None = None   # (clock, done) on settling

    @property
    def phase(self) -> Phase:
        return self.phases[self.index]

    @property
    def done(self) -> float:
        """Units of the current phase done."""
        return self._done

    def enter(self, name: str, work: float | None = None, offset: float = 0.0) -> None:
        """Start phase ``name`` (the phases before it end now); ``work`` re-sizes it (a
        drain's vehicles, known at its start) and ``offset`` is subtracted from every
        ``done`` given to :meth:`update` (a control window that starts at t = 600 s)."""
        names = [p.name for p in self.phases]
        if name not in names[self.index:]:
            raise ValueError(f"phase {name!r} is not ahead; expected one of "
                             f"{names[self.index:]}")
        now = self.clock()
        self._finish(now)
        for skipped in self.phases[self.index + 1:names.index(name)]:
            self.durations[skipped.name] = 0.0
        self.index = names.index(name)
        if work is not None:
            p = self.phase
            self.phases[self.index] = Phase(p.name, max(work, 1e-9), p.cost, p.settle, p.unit)
        self._entered, self._done, self._offset = now, 0.0, offset
        self._samples.clear()
        self._settled_at = None

    def finish(self) -> None:
        """End the current phase, and with it the run."""
        self._finish(self.clock())
        self._done = self.phase.work

    def _finish(self, now: float) -> None:
        if self.phase.name in self.durations:
            return
        self.durations[self.phase.name] = now - self._entered
        if self._settled_at is not None:      # the whole settled part, not just the window
            t0, d0 = self._settled_at
            self._calibrate(now - t0, self.phase.work - d0)
        elif now > self._entered and self.phase.settle == 0:
            self._calibrate(now - self._entered, self.phase.work)

    def _calibrate(self, seconds: float, units: float) -> None:
        p = self.phase
        if seconds > 0 and units > 0 and p.cost > 0:
            self._per_cost = seconds / (units * p.cost / p.work)

    def update(self, done: float) -> None:
        """``done`` units of the current phase (less its ``offset``)."""
        now = self.clock()
        p = self.phase
        self._done = min(max(done - self._offset, 0.0), p.work)
        if self._done < p.settle * p.work:
            return
        if self._settled_at is None:
            self._settled_at = (now, self._done)
        self._samples.append((now, self._done))
        while len(self._samples) > 2 and self._samples[1][0] <= now - self.window:
            self._samples.popleft()

    def _rate(self) -> float | None:
        """Units per second of the current phase over the window, None before a rate."""
        if len(self._samples) < 2:
            return None
        (t0, d0), (t1, d1) = self._samples[0], self._samples[-1]
        return (d1 - d0) / (t1 - t0) if t1 > t0 and d1 > d0 else None

    def fraction(self) -> float:
        """Share of the run's expected cost done (0-1)."""
        total = sum(p.cost for p in self.phases)
        if total <= 0:
            return self.index / len(self.phases)
        before = sum(p.cost for p in self.phases[:self.index])
        return min(1.0, (before + self.phase.cost * self._done / self.phase.work) / total)

    def seconds_left(self) -> float | None:
        """Seconds left in the run; None while no rate has been measured."""
        p = self.phase
        rate = self._rate()
        per_cost = self._per_cost
        if rate is not None and p.cost > 0:
            per_cost = p.work / (rate * p.cost)
        if per_cost is None:
            return None
        left_here = (p.work - self._done) / rate if rate is not None else \
            max(p.cost * per_cost * (1 - self._done / p.work)
                - (self.clock() - self._entered if self._done == 0 else 0.0), 0.0)
        return left_here + per_cost * sum(q.cost for q in self.phases[self.index + 1:])


class RunProgress:
    """A progress bar over named phases, saying which one runs and an honest time left.

    On a terminal the bar redraws in place at most every ``interval`` seconds; otherwise
    one line when a phase starts and at each tenth of the run. Use as a context manager
    or call :meth:`close`, which prints the phases' wall times.
    """

    def __init__(self, phases: Sequence[Phase], label: str = "", enabled: bool = True,
                 stream: TextIO | None = None, interval: float = 0.5,
                 clock: Clock = time.perf_counter) -> None:
        self.timer = PhaseClock(phases, clock)
        self.label, self.enabled, self.interval = label, enabled, interval
        self.stream = stream or sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last, self._tenth = -1e9, -1
        self._closed = False

    def enter(self, name: str, work: float | None = None, offset: float = 0.0) -> None:
        """Start phase ``name`` (see :meth:`PhaseClock.enter`) and say so."""
        self.timer.enter(name, work, offset)
        self._draw()

    def update(self, done: float) -> None:
        """``done`` units of the current phase."""
        self.timer.update(done)
        if not self.enabled:
            return
        now = self.timer.clock()
        tenth = int(self.timer.fraction() * 10)
        if (self.tty and now - self._last >= self.interval) or (
                not self.tty and tenth != self._tenth):
            self._draw()

    def line(self) -> str:
        """The bar as one line of at most 100 characters."""
        t = self.timer
        p = t.phase
        frac = t.fraction()
        bar = "#" * int(frac * 20)
        where = f"{t.index + 1}/{len(t.phases)} {p.name}"
        if p.unit:
            where += f" {t.done:.0f}/{p.work:.0f} {p.unit}"
        left = t.seconds_left()
        left_text = "left: measuring" if left is None else f"left ~{duration_text(left)}"
        elapsed = duration_text(t.clock() - t.start)
        return f"{self.label} [{bar:<20}] {frac:4.0%} {where}  {elapsed}, {left_text}"[:100]

    def _draw(self) -> None:
        if not self.enabled:
            return
        self._last, self._tenth = self.timer.clock(), int(self.timer.fraction() * 10)
        text = self.line()
        self.stream.write(f"\r{text:<100}" if self.tty else text + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the run (once): a last line with the wall time of each phase."""
        if self._closed:
            return
        self._closed = True
        t = self.timer
        t.finish()
        if not self.enabled:
            return
        times = ", ".join(f"{name} {s:.0f} s" for name, s in t.durations.items())
        end = textwrap.fill(f"{self.label} took {duration_text(t.clock() - t.start)}: "
                            f"{times}", 100, subsequent_indent="  ")
        self.stream.write(f"\r{end:<100}\n" if self.tty else end + "\n")
        self.stream.flush()

    def abandon(self) -> None:
        """End the run on an error: the line ends, no phase times."""
        if self._closed:
            return
        self._closed = True
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self) -> RunProgress:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *rest: object) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abandon()
