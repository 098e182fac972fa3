"""Newell's three-detector method: the kinematic-wave replay a second-order model is judged by.

The classical reference for a replay error (``docs/identify.md``, 'What a replay error is
judged against'): the section's interior from its two boundary counts and its initial
state alone, by the exact solution of the LWR model with a triangular fundamental diagram
(Newell 1993, "A simplified theory of kinematic waves", parts I-II; Daganzo 2005's
variational form). Waves entering at x = L travel upstream at the congested branch's
slope, undamped and unamplified; the classes travel with their vehicles (FIFO).

With N(x, t) the cumulative count (vehicle labels, decreasing downstream), free-flow speed
``v_free``, wave speed ``w`` (> 0, upstream) and jam density ``rho_jam``:

* N(x, t) = min of N(0, t - x / v_free), N(L, t - (L - x) / w) + rho_jam (L - x), and,
  for the vehicles of t = 0, min over y in [x - v_free t, x + w t] of
  N(y, 0) + q_max t - rho_crit (x - y) (the triangle's cost of a straight path is linear
  in its slope, so the minimum over paths is the minimum over their origins y);
* the density of a cell is the label difference across it over its length;
* the AV density is the AV-count difference of the same labels: a label entered at x = 0
  at time s carries the AV count that had crossed x = 0 by s, a label of the initial state
  the AV count downstream of its place.

All SI: m, s, veh/m, veh/s. Pure numpy; :func:`three_detector_fields` is vectorised over
cells and periods.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import require
from arzsumo.identify.data import IdentifyError, ReplayData


@dataclass(frozen=True)
class Triangle:
    """The triangular fundamental diagram q(rho) = min(v_free rho, w (rho_jam - rho)).

    ``v_free`` and ``w`` in m/s (both > 0; ``w`` is the upstream wave speed's magnitude),
    ``rho_jam`` in veh/m (> 0).
    """

    v_free: float
    w: float
    rho_jam: float

    def __post_init__(self) -> None:
        for name in ("v_free", "w", "rho_jam"):
            value = getattr(self, name)
            require(math.isfinite(value) and value > 0, name, value, "a finite value > 0",
                    IdentifyError)

    @property
    def rho_crit(self) -> float:
        """The critical density, veh/m."""
        return self.w * self.rho_jam / (self.v_free + self.w)

    @property
    def capacity(self) -> float:
        """q_max, veh/s."""
        return self.v_free * self.rho_crit

    @classmethod
    def through(cls, v_free: float, w: float, rho: float, q: float) -> Triangle:
        """The triangle whose congested branch of slope -``w`` passes through the
        operating point (``rho`` veh/m, ``q`` veh/s): rho_jam = rho + q / w."""
        return cls(v_free, w, rho + q / w)


def _cumulative(flow: np.ndarray, dt: np.ndarray, start: float) -> np.ndarray:
    """Counts at the period ends (``start`` at t = 0 prepended) of per-period flows."""
    return start + np.concatenate([[0.0], np.cumsum(flow * dt)])


def _at(times: np.ndarray, counts: np.ndarray, when: np.ndarray) -> np.ndarray:
    """Counts interpolated at ``when``; +inf before t = 0 (the path does not exist)."""
    return np.where(when >= 0.0, np.interp(when, times, counts), np.inf)


@dataclass(frozen=True)
class _Counts:
    """The counts the method starts from (module docstring), SI."""

    edges: np.ndarray      # cell edges, m from x = 0 (N + 1,)
    times: np.ndarray      # 0 and the period ends, s (T + 1,)
    n0: np.ndarray         # N(edge, 0): 0 at x = 0, negative downstream
    a0: np.ndarray         # the AV count A(edge, 0), likewise
    up: np.ndarray         # N(0, t) at ``times``: the inflow cumulated
    a_up: np.ndarray       # A(0, t) at ``times``
    down: np.ndarray       # N(L, t) at ``times``: N(L, 0) plus the outflow cumulated


def _counts(data: ReplayData) -> _Counts:
    """The initial state's and the boundaries' cumulative counts of ``data``."""
    dx = float(np.diff(data.x).mean())
    edges = np.arange(data.x.size + 1) * dx
    times = np.concatenate([[0.0], data.t])
    dt = np.diff(times)
    n0 = np.concatenate([[0.0], -np.cumsum((data.initial[0] + data.initial[2]) * dx)])
    a0 = np.concatenate([[0.0], -np.cumsum(data.initial[2] * dx)])
    inflow_a = data.inlet[:, 2] * data.inlet[:, 3]
    inflow = data.inlet[:, 0] * data.inlet[:, 1] + inflow_a
    return _Counts(edges, times, n0, a0, _cumulative(inflow, dt, 0.0),
                   _cumulative(inflow_a, dt, 0.0), _cumulative(data.outflow, dt, n0[-1]))


def labels(data: ReplayData, fd: Triangle) -> np.ndarray:
    """N(x, t) at the cell edges (T, N + 1), label 0 at x = 0 at t = 0 (docstring)."""
    c = _counts(data)
    length = c.edges[-1]
    t, x = data.t[:, None], c.edges[None, :]
    from_up = _at(c.times, c.up, t - x / fd.v_free)
    from_down = _at(c.times, c.down, t - (length - x) / fd.w) + fd.rho_jam * (length - x)
    # the initial state: N(y, 0) is linear within cells, so the least cost over the
    # origins within reach is at an edge or at an end of the reach
    lo = np.clip(x - fd.v_free * t, 0.0, length)
    hi = np.clip(x + fd.w * t, 0.0, length)
    ends = np.stack([lo, hi], axis=-1)
    y = np.concatenate([np.broadcast_to(c.edges, lo.shape + c.edges.shape), ends], axis=-1)
    inside = (y >= lo[..., None]) & (y <= hi[..., None])
    cost = (np.interp(y, c.edges, c.n0) + fd.capacity * t[..., None]
            - fd.rho_crit * (x[..., None] - y))
    from_start = np.where(inside, cost, np.inf).min(axis=-1)
    return np.minimum(np.minimum(from_up, from_down), from_start)


def av_count_of_label(data: ReplayData) -> tuple[np.ndarray, np.ndarray]:
    """(labels, AV counts), both increasing: the AV count A(n) at label n (docstring).

    The initial state's edges carry N(e, 0) and A(e, 0) (both 0 at x = 0, negative
    downstream); labels entered later carry the counts that had crossed x = 0 by then.
    """
    c = _counts(data)
    return (np.concatenate([c.n0[::-1], c.up[1:]]),
            np.concatenate([c.a0[::-1], c.a_up[1:]]))


def three_detector_fields(data: ReplayData, fd: Triangle) -> np.ndarray:
    """The densities (T, 4, N) Newell's method gives on ``data``'s cells and periods:
    (rho_h, NaN, rho_a, NaN), veh/m; speeds are not predicted."""
    dx = np.diff(data.x).mean()
    n = labels(data, fd)
    known_n, known_a = av_count_of_label(data)
    a = np.interp(n, known_n, known_a)
    rho = -np.diff(n, axis=1) / dx
    rho_a = np.clip(-np.diff(a, axis=1) / dx, 0.0, rho)
    out = np.full((data.t.size, 4, data.x.size), np.nan)
    out[:, 0], out[:, 2] = rho - rho_a, rho_a
    return out
