"""A law designed for a unit actuator, on a meter whose release moves the outflow g times.

The closed loop realises the paper's boundary input U (clpsys4) by a change of the ramp
meter's release, r = r_nominal - U_cmd (:func:`arzsumo.sumo.meter_release.release_rate_for`),
which assumes dq(L) / dr = -1; SUMO's merge is measured at about -2 (the premise's
actuator staircase, research/premise.md). :class:`MeterGain` hands the meter U_cmd = U / g
and tells the law what reached the boundary in its own units: g times the U applied and
g times the range in force (anti-windup), so the delay compensator and the event trigger
inside it see outflow changes, as in the paper.
"""

from __future__ import annotations

import math

from arzsumo.control.base import Controller, ControlLog, MacroState
from arzsumo.errors import ModelError, require


class MeterGain(Controller):
    """``inner`` (a law whose U is the outflow deviation it wants at x = L, veh/s) on a
    meter of gain ``gain`` (-dq(L) / dr, > 0; 1: the unit actuator).

    The log holds what the meter is asked for (U / g, veh/s), with the inner law's
    events and diagnostics.
    """

    def __init__(self, inner: Controller, gain: float) -> None:
        require(math.isfinite(gain) and gain > 0, "meter_gain", gain, "a gain > 0",
                ModelError)
        super().__init__()
        self.inner, self.gain = inner, float(gain)
        self.name = inner.name

    def reset(self) -> None:
        super().reset()
        self.inner.reset()

    def decide(self, state: MacroState) -> float:
        u = self.inner.check(state) / self.gain
        inner: ControlLog = self.inner.log
        u_cont = inner.u_continuous[-1] / self.gain if inner.u_continuous else u
        triggered = bool(inner.triggered[-1]) if inner.triggered else True
        self.log.record(state.t, u, u_cont, triggered,
                        **{k: v[-1] for k, v in inner.extra.items() if v})
        return u

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        """The U applied and its range (veh/s, meter units), told in outflow units."""
        g = self.gain
        self.inner.applied(u * g, lower * g, upper * g)

    def actuated(self, u: float) -> None:
        self.inner.actuated(u * self.gain)

    @property
    def has_trigger(self) -> bool:
        """The inner law's."""
        return self.inner.has_trigger

    def set_output_noise(self, sd: float) -> bool:
        """``sd`` in meter units (veh/s), handed on in outflow units."""
        return self.inner.set_output_noise(sd * self.gain)
