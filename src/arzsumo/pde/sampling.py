"""What a twin run records besides its state: output samples and controller checks."""

from __future__ import annotations

import math

import numpy as np

from arzsumo.control.base import Controller, MacroState


class Samples:
    """Primitive fields sampled every output period (preallocated)."""

    def __init__(self, horizon: float, period: float, cells: int) -> None:
        n = math.floor(horizon / period + 1e-9) + 1
        self.t, self.f, self.k = np.empty(n), np.empty((n, 4, cells)), 0
        self.period = period

    def due(self, t: float, eps: float) -> bool:
        return self.k < self.t.size and t >= self.k * self.period - eps

    def take(self, t: float, fields: np.ndarray) -> None:
        self.t[self.k], self.f[self.k] = t, fields
        self.k += 1


class Checks:
    """The controller's checks, once per control period: U held between them, saturated
    to [u_min, u_max] (paper, section 5: -q* .. q* by default), and the time it spent
    saturated (s)."""

    def __init__(self, ctrl: Controller, period: float, horizon: float,
                 bounds: tuple[float, float]) -> None:
        self.ctrl, self.period, self.horizon, self.bounds = ctrl, period, horizon, bounds
        self.t: list[float] = []
        self.u: list[float] = []
        self.requested: list[float] = []
        self.held, self.saturated, self.k = 0.0, 0.0, 0

    def due(self, t: float, eps: float) -> bool:
        return t >= self.k * self.period - eps

    def check(self, t: float, state: MacroState) -> None:
        requested = float(self.ctrl.check(state))
        self.held = min(max(requested, self.bounds[0]), self.bounds[1])
        if self.held != requested:
            self.saturated += min(self.period, self.horizon - t)
        self.t.append(t)
        self.u.append(self.held)
        self.requested.append(requested)
        self.k += 1
