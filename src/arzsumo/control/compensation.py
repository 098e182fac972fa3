"""Delay compensation: a PDE law evaluated on the state predicted theta seconds ahead.

:class:`DelayCompensated` wraps continuous backstepping (control_law) or the full-state
ETC (control law sam with defdynamic): at each check t it predicts w-bar(t + theta)
(clpsys1) with the commands applied in [t - theta, t) (:mod:`arzsumo.control.predictor`)
and evaluates the wrapped law on it; with theta = 0 the command is the wrapped law's
exactly. docs/sumo.md, "Actuation limits" (delay compensation).
"""

from __future__ import annotations

import math

import numpy as np

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import Controller, ControlLog, MacroState
from arzsumo.control.etc import EventTriggered
from arzsumo.control.predictor import committed, predict_riemann
from arzsumo.errors import ModelError, require

#: the laws on scaled Riemann states :class:`DelayCompensated` wraps (the acting
#: backstepping or ETC, :data:`arzsumo.bridge.delay.COMPENSATED`)
RiemannLaw = Backstepping | EventTriggered


class DelayCompensated(Controller):
    """``inner`` (a :class:`RiemannLaw`) evaluated on the state predicted ``delay`` s
    (theta, in [0, L / max |lambda|)) ahead (module docstring).

    The log is the inner law's (same records as without compensation); the applied
    commands are kept in :attr:`times` (s) and :attr:`u_bar` (scaled, clpsys4).
    """

    def __init__(self, inner: RiemannLaw, delay: float) -> None:
        self.inner = inner
        system = inner.lin.system
        horizon = system.length / float(np.abs(system.lam).max())
        require(math.isfinite(delay) and 0.0 <= delay < horizon, "delay", delay,
                f"a dead time in [0, {horizon:.4g}) s", ModelError)
        self.delay = float(delay)
        self.name = inner.name
        super().__init__()
        self.times: list[float] = []
        self.u_bar: list[float] = []

    @property
    def log(self) -> ControlLog:
        return self.inner.log

    @log.setter
    def log(self, value: ControlLog) -> None:
        self.inner.log = value

    def reset(self) -> None:
        self.inner.reset()
        self.times, self.u_bar = [], []

    def predicted(self, t: float, w_bar: np.ndarray) -> np.ndarray:
        """w-bar(t + theta) from w-bar(t) on the kernel grid and the commands applied
        before t (scaled Riemann variables, clpsys1)."""
        ahead = committed(np.asarray(self.times), np.asarray(self.u_bar), t, self.delay)
        return predict_riemann(self.inner.lin.system, self.inner.state_map.x, w_bar,
                               self.delay, ahead)

    def decide(self, state: MacroState) -> float:
        sm = self.inner.state_map
        w_bar = sm.riemann(sm.deviations(state))
        u_bar = self.inner.check_riemann(state.t, self.predicted(state.t, w_bar))
        self.times.append(float(state.t))        # the command, until the meter's is known
        self.u_bar.append(float(u_bar))
        return u_bar / self.inner.lin.u_bar_per_u

    def actuated(self, u: float) -> None:
        """The meter received ``u`` (veh/s) for the last check: the prediction uses it."""
        if self.u_bar:
            self.u_bar[-1] = u * self.inner.lin.u_bar_per_u

    @property
    def has_trigger(self) -> bool:
        """The inner law's."""
        return self.inner.has_trigger

    def set_output_noise(self, sd: float) -> bool:
        """Handed to the inner law (its trigger's dead band; veh/s)."""
        return self.inner.set_output_noise(sd)

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        """Anti-windup: handed to the inner law (the ETC's trigger projects on the range)."""
        self.inner.applied(u, lower, upper)
