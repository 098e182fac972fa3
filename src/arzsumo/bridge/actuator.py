"""The actuation stage of the closed loop: the controller's U, limited, to a ramp-meter command.

U (veh/s) is the deviation of the section's outflow from q* (paper, section 2): the meter is
asked for the outflow ``q_nominal + U`` on its calibrated curve, so U = 0 is the nominal
plan; the open loop keeps that plan and never commands the meter. The ``[actuation]``
limits act in :func:`limit_u` (range, rate, range again); with ``hold_plan_in_range`` a
held U keeps its plan while it lies in the range (:meth:`MeterActuator._keeps_plan`);
while the queue override is on, the range collapses to the override's U, a saturation to
the law. :func:`command_meter` is the one place the meter's command is clamped to the
plan's bounds. docs/sumo.md, 'Actuation limits'; docs/outputs.md, 'Counts'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple, Protocol

from arzsumo.control.base import Applied, Controller
from arzsumo.control.meter_gain import MeterGain
from arzsumo.control.registry import is_pde
from arzsumo.scenario.actuation import ActuationSettings
from arzsumo.sumo.meter import MeterLight

INF = math.inf


class Limited(NamedTuple):
    """What :func:`limit_u` did: the U applied (veh/s) and which limits acted."""

    u_applied: float
    saturated: bool
    rate_limited: bool


def limit_u(u_raw: float, u_prev: float, lower: float = -INF, upper: float = INF,
            rate_step: float = INF) -> Limited:
    """The U applied for the law's ``u_raw`` (veh/s): range, then rate, then range.

    ``u_prev`` is the U applied in the previous period (0 before the first), ``lower``,
    ``upper`` the range and ``rate_step`` the largest change per period (u_rate_max x
    Delta), all veh/s (infinite: off). ``u_applied`` always lies in the range;
    ``saturated`` where the range cut, ``rate_limited`` where the rate did.
    """
    u = min(max(u_raw, lower), upper)
    saturated = u != u_raw
    v = min(max(u, u_prev - rate_step), u_prev + rate_step)
    rate_limited = v != u
    w = min(max(v, lower), upper)
    return Limited(w, saturated or w != v, rate_limited)


def on_meter(ctrl: Controller, acting: str, settings: ActuationSettings) -> Controller:
    """``ctrl`` asking the meter for U / ``meter_gain`` when ``acting`` is a PDE law and
    the gain is not 1 (:class:`~arzsumo.control.meter_gain.MeterGain`); ``ctrl`` itself
    otherwise (ALINEA and the held meter command release rates directly; on the outlet's
    speed limit the actuator maps U itself, :mod:`arzsumo.bridge.speed_actuator`)."""
    if settings.meter_gain == 1.0 or not is_pde(acting) or settings.actuator != "meter":
        return ctrl
    return MeterGain(ctrl, settings.meter_gain)


def command_meter(meter: MeterLight, u: float, q_nominal: float) -> float:
    """Command ``meter`` with the outflow deviation ``u`` (veh/s) from ``q_nominal``
    (veh/s): its plan variable for ``u``, saturated to the plan's bounds. Returns the
    green share of the plan requested."""
    lo, hi = meter.plan_bounds
    return meter.set_plan(min(hi, max(lo, meter.plan_for(u, q_nominal))))


@dataclass(frozen=True)
class ActuationLimits:
    """The ``[actuation]`` limits in SI for one run: ``u_max`` (veh/s) and ``rate_step``
    (veh/s per control period; inf: off); ``ramp_bound``: U within the meter's range and
    above the ramp's floor; ``hold_plan``: a held U keeps its plan while in the range."""

    u_max: float = INF
    rate_step: float = INF
    ramp_bound: bool = False
    hold_plan: bool = False

    @classmethod
    def of(cls, settings: ActuationSettings, q_nominal: float,
           control_period: float) -> ActuationLimits:
        """The limits of ``settings`` (0: off) around ``q_nominal`` (veh/s), for a control
        period of ``control_period`` s."""
        return cls(settings.u_max_fraction * q_nominal if settings.u_max_fraction else INF,
                   settings.u_rate_max * control_period if settings.u_rate_max else INF,
                   settings.ramp_bound, settings.hold_plan_in_range)

    def range(self, meter: MeterLight, q_nominal: float) -> tuple[float, float]:
        """``(lower, upper)`` of U (veh/s) for ``meter`` with its present ramp queue."""
        lower, upper = -self.u_max, self.u_max
        if self.ramp_bound:
            lo, hi = meter.u_range(q_nominal)
            lower = max(lower, lo, meter.ramp_floor(meter.queue, q_nominal))
            upper = min(upper, hi)
        return lower, upper


@dataclass(frozen=True)
class Actuation:
    """One command: the law's U and the U applied (veh/s), the limit flags, the range
    ``[lower, upper]`` (veh/s) in force, the green share commanded and the release rate
    asked of the meter (veh/s; NaN for a fixed cycle), and the outlet's speed limit
    commanded (m/s; NaN when the meter is the actuator,
    :mod:`arzsumo.bridge.speed_actuator`)."""

    u_raw: float
    u_applied: float
    saturated: bool
    rate_limited: bool
    lower: float
    upper: float
    green: float
    release_rate: float = math.nan
    speed_limit: float = math.nan

    def told(self, anti_windup: bool) -> Applied:
        """What the controller is told at its next check: the U applied and, with
        ``anti_windup``, the range in force."""
        if anti_windup:
            return Applied(self.u_applied, self.lower, self.upper)
        return Applied(self.u_applied, anti_windup=False)


class Actuator(Protocol):
    """The actuation stage's interface: the meter (:class:`MeterActuator`) or the outlet's
    speed limit (:class:`arzsumo.bridge.speed_actuator.SpeedLimitActuator`)."""

    def apply(self, u: float) -> Actuation:
        """Command U (veh/s), limited; what was applied."""

    def summary(self) -> dict[str, Any]:
        """The actuator's own counts over the control window, beside the meter's."""

    def restore(self) -> None:
        """The open loop's command again, for the drain after the window."""


class MeterActuator:
    """Commands ``meter`` with the outflow ``q_nominal + U`` (veh/s), U limited by ``limits``
    (default: none); ``hold_nominal`` (the open loop) keeps the nominal plan whatever U is."""

    def __init__(self, meter: MeterLight, q_nominal: float, hold_nominal: bool,
                 limits: ActuationLimits | None = None) -> None:
        self.meter, self.q_nominal, self.hold_nominal = meter, q_nominal, hold_nominal
        self.limits = limits or ActuationLimits()
        self.u_prev = 0.0
        self.u_raw_prev: float | None = None
        self.range_prev = (-INF, INF)

    def apply(self, u: float) -> Actuation:
        """Command U (veh/s), limited; what was applied."""
        meter = self.meter
        if self.hold_nominal:
            return Actuation(u, 0.0, False, False, -INF, INF, meter.green_share,
                             release_rate(meter))
        lower, upper = self.limits.range(meter, self.q_nominal)
        rate_step = self.limits.rate_step
        if meter.override():
            # the queue override runs the meter at its largest release whatever is
            # commanded: to the law, a saturation of its actuator (anti-windup sees it)
            lower = upper = meter.override_u(self.q_nominal)
            rate_step = INF
        lim = limit_u(u, self.u_prev, lower, upper, rate_step)
        if self._keeps_plan(u, lower, upper, rate_step):
            lim = Limited(self.u_prev, lim.saturated, False)
        else:                  # the range the plan was set under
            self.range_prev = (lower, upper)
        self.u_raw_prev = u
        self.u_prev = lim.u_applied
        green = command_meter(meter, lim.u_applied, self.q_nominal)
        return Actuation(u, lim.u_applied, lim.saturated, lim.rate_limited, lower, upper,
                         green, release_rate(meter))

    def summary(self) -> dict[str, Any]:
        """Nothing beside the meter's own counts."""
        return {}

    def restore(self) -> None:
        """Nothing: the drain hands the meter to its own policy."""

    def _keeps_plan(self, u: float, lower: float, upper: float, rate_step: float) -> bool:
        """Whether a held ``u`` keeps the previous U applied (docs/outputs.md, 'Counts'):
        held, settled under the range the plan was set under, and inside the new one."""
        if not self.limits.hold_plan or u != self.u_raw_prev:
            return False
        settled = limit_u(u, self.u_prev, *self.range_prev, rate_step).u_applied
        return settled == self.u_prev and lower <= self.u_prev <= upper


def release_rate(meter: MeterLight) -> float:
    """The release rate ``meter`` was asked for, veh/s (NaN for a fixed cycle)."""
    rate = meter.release_rate
    return math.nan if rate is None else rate
