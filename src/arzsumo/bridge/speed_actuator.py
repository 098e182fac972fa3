"""The actuation stage on the outlet's speed limit: a PDE law's U as mainstream control.

The limit of the edge past the merge is v = v_nominal + U / g (paper's U, clpsys4; g =
``speed_limit_gain`` = dq(L)/dv, veh/m), rounded and kept in range by :func:`limit_for`;
the U applied is what that limit realises on the linear map, g (v - v_nominal). The
``[actuation]`` limits act first, as for the meter (:func:`~arzsumo.bridge.actuator.limit_u`);
``ramp_bound`` and the queue override do not act, and the meter keeps its nominal plan.
docs/sumo.md, 'The outlet's speed limit as the actuator'.
"""

from __future__ import annotations

import math
from typing import Any

from arzsumo.bridge.actuator import Actuation, ActuationLimits, MeterActuator, limit_u, release_rate
from arzsumo.control.registry import is_pde
from arzsumo.scenario.actuation import ActuationSettings
from arzsumo.sumo.meter import MeterLight
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.speed_limit import OutletSpeedLimit


def limit_for(u: float, nominal: float, settings: ActuationSettings) -> float:
    """The speed limit (m/s) that realises the outflow deviation ``u`` (veh/s) about
    ``nominal`` (m/s, the open loop's limit): ``nominal + u / gain``, a whole number of
    ``speed_limit_step`` from ``nominal`` (any value with step 0), within the range."""
    dv = u / settings.speed_limit_gain
    step = settings.speed_limit_step
    if step > 0:
        dv = step * round(dv / step)
    return min(settings.speed_limit_max, max(settings.speed_limit_min, nominal + dv))


def u_range(nominal: float, settings: ActuationSettings, u_max: float = math.inf
            ) -> tuple[float, float]:
    """``(lower, upper)`` of U (veh/s): the limit's range about ``nominal`` (m/s) on the
    linear map, cut to ``|U| <= u_max``."""
    g = settings.speed_limit_gain
    return (max(-u_max, g * (settings.speed_limit_min - nominal)),
            min(u_max, g * (settings.speed_limit_max - nominal)))


class SpeedLimitActuator:
    """Commands the outlet's speed limit (``outlet``, its nominal the network's) with U
    (veh/s), limited by ``limits`` (the meter's ``ramp_bound`` does not act); ``meter``
    stays at its nominal plan, read for the record only."""

    def __init__(self, outlet: OutletSpeedLimit, meter: MeterLight,
                 settings: ActuationSettings, limits: ActuationLimits) -> None:
        self.outlet, self.meter, self.settings, self.limits = outlet, meter, settings, limits
        self.range = u_range(outlet.nominal, settings, limits.u_max)
        self.u_prev = 0.0

    def apply(self, u: float) -> Actuation:
        """Command U (veh/s), limited; return what was applied (the speed limit in m/s)."""
        lower, upper = self.range
        lim = limit_u(u, self.u_prev, lower, upper, self.limits.rate_step)
        nominal, g = self.outlet.nominal, self.settings.speed_limit_gain
        speed = limit_for(lim.u_applied, nominal, self.settings)
        applied = g * (speed - nominal)
        if abs(applied - self.u_prev) > self.limits.rate_step + 1e-12:
            # rounded past the rate limit: the grid's next limit toward the previous one
            back = self.settings.speed_limit_step * (1 if applied < self.u_prev else -1)
            speed = limit_for(g * (speed + back - nominal), nominal, self.settings)
            applied = g * (speed - nominal)
        self.outlet.set(speed)
        self.u_prev = applied
        return Actuation(u, applied, lim.saturated, lim.rate_limited, lower, upper,
                         self.meter.green_share, release_rate(self.meter), speed_limit=speed)

    def summary(self) -> dict[str, Any]:
        """The outlet's changes over the window and its limits (m/s)."""
        return self.outlet.summary()

    def restore(self) -> None:
        """The outlet back at its nominal limit (the drain after the window runs the open
        loop's outlet, whatever the law did), not counted as a change."""
        self.outlet.restore()


def actuator_for(plant: SumoPlant, q_nominal: float, controller: str, acting: str,
                 settings: ActuationSettings, period: float
                 ) -> MeterActuator | SpeedLimitActuator:
    """The actuation stage of a run: the outlet's speed limit when ``settings`` says so
    and ``acting`` is a PDE law, else the meter (held at its nominal plan for the open
    loop, ``controller`` "open"). ``q_nominal`` (veh/s) is the nominal plan's outflow,
    ``period`` the control period (s)."""
    limits = ActuationLimits.of(settings, q_nominal, period)
    if settings.actuator == "speed_limit" and is_pde(acting):
        return SpeedLimitActuator(plant.outlet_speed_limit(), plant.meter, settings,
                                  limits)
    return MeterActuator(plant.meter, q_nominal, controller == "open", limits)
