"""Event metrics of a controller run (section 5): triggers, release time, intervals, and the
Lyapunov convergence time of the sensitivity subsection."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.control.base import ControlLog


def release_time(t: ArrayLike, triggered: ArrayLike, horizon: float) -> float:
    """Total release time (s): the time during which the applied control stayed unchanged.

    ``t`` are the check times, s, increasing (a :class:`ControlLog`'s ``t``); ``triggered``
    whether each check updated the control (a log's ``triggered``, or the twin's
    :func:`arzsumo.pde.metrics.events`); ``horizon`` the end of the run, s.

    Every check that does not update the control releases the signal until the next check
    (the last one until ``horizon``). With checks every Delta from t = 0 this is
    T - N Delta for N events (t_0 included), which matches the paper's pairs (160, 291 s),
    (101, 349 s), (245, 206 s), (358, 93 s) over T = 450 s to within one period; an empty
    log (no check, so no update) gives ``horizon`` (N = 0).
    """
    t = np.asarray(t, float)
    if t.size == 0:
        return float(horizon)
    spans = np.diff(np.append(t, max(horizon, t[-1])))
    return float(np.sum(spans[~np.asarray(triggered, bool)]))


def lyapunov_convergence_time(t: np.ndarray, V: np.ndarray, fraction: float = 0.01) -> float:
    """First time (s) after which V stays below ``fraction`` V(0); inf if it never does."""
    t, V = np.asarray(t), np.asarray(V)
    above = np.nonzero(fraction * V[0] < V)[0]
    if above.size == 0:
        return float(t[0])
    if above[-1] == V.size - 1:
        return float("inf")
    return float(t[above[-1] + 1])


@dataclass(frozen=True)
class EventSummary:
    """Counts and times of a controller run; times in s."""

    triggers: int
    release_time: float
    min_interval: float
    mean_interval: float


def event_summary(log: ControlLog, horizon: float) -> EventSummary:
    """Trigger count, release time and inter-event intervals of ``log``."""
    intervals = np.diff(log.event_times)
    return EventSummary(
        triggers=log.triggers, release_time=release_time(log.t, log.triggered, horizon),
        min_interval=float(intervals.min()) if intervals.size else float("inf"),
        mean_interval=float(intervals.mean()) if intervals.size else float("inf"))
