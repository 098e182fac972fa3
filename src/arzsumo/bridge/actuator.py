"""The actuation stage of the closed loop: the controller's U, limited, to a ramp-meter command.

A PDE controller's U (veh/s) is the deviation of the section's outflow from q* (paper,
section 2; the boundary input of control_law): the meter is asked for the mainline outflow
``q_nominal + U``, where ``q_nominal`` is the outflow of the nominal plan on the meter's
calibrated curve, so U = 0 is the open loop. The open loop itself never commands the
meter: it keeps the nominal plan, and no plan change is counted.

Between the controller and the meter, the ``[actuation]`` limits
(:mod:`arzsumo.scenario.actuation`) act in :func:`limit_u`, in this order:

1. the range ``[lower, upper]``: ``|U| <= u_max_fraction q*`` and, with ``ramp_bound``,
   :func:`ramp_range`; the law's U outside it is *saturated*;
2. the rate: ``|U_k - U_{k-1}| <= u_rate_max Delta`` from the U applied in the previous
   period (0, the nominal plan, before the first); a change cut there is *rate limited*;
3. the range again, so the output always lies in it: the range wins over the rate when
   the range moved away from the previous U (the ramp bound moves with the queue).

Every limit off (the default) returns the law's U unchanged. While the meter's queue
override is on (the ramp queue beyond its storage,
:meth:`~arzsumo.sumo.meter.MeterLight.override`) the range collapses to the override's U,
whatever the limits: the law sees a saturated actuator. The U applied goes back to the
controller (:meth:`arzsumo.control.base.Controller.applied`, with the range) unless
``anti_windup = false``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from arzsumo.scenario.actuation import ActuationSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.meter import GreenShareCurve, MeterLight

INF = math.inf


class Limited(NamedTuple):
    """What :func:`limit_u` did: the U applied (veh/s) and which limits acted."""

    u_applied: float
    saturated: bool
    rate_limited: bool


def limit_u(u_raw: float, u_prev: float, lower: float = -INF, upper: float = INF,
            rate_step: float = INF) -> Limited:
    """The U applied for the law's ``u_raw`` (veh/s): range, then rate, then range.

    Parameters
    ----------
    u_raw : float
        The controller's U, veh/s.
    u_prev : float
        The U applied in the previous control period, veh/s (0 before the first).
    lower, upper : float
        The range of U, veh/s (``lower <= upper``; infinite: off).
    rate_step : float
        Largest change of U over one control period, veh/s (u_rate_max x Delta; inf: off).

    Returns
    -------
    Limited
        ``u_applied`` in ``[lower, upper]`` always, within ``rate_step`` of ``u_prev``
        whenever ``u_prev`` lies in the range; ``saturated`` where ``u_raw`` (or the
        rate-limited value) lay outside the range, ``rate_limited`` where the rate cut it.
    """
    u = min(max(u_raw, lower), upper)
    saturated = u != u_raw
    v = min(max(u, u_prev - rate_step), u_prev + rate_step)
    rate_limited = v != u
    w = min(max(v, lower), upper)
    return Limited(w, saturated or w != v, rate_limited)


def meter_range(curve: GreenShareCurve, cfg: SumoConfig, q_nominal: float) -> tuple[float, float]:
    """The U (veh/s) the meter can command: the monotone curve's outflow between
    ``green_share_max`` (least mainline outflow) and ``green_share_min``, minus q*; widened
    to include 0 (the nominal plan is always allowed). One per green: U = r_nominal - r
    for r in [``release_rate_min``, ``release_rate_max``]
    (:func:`~arzsumo.sumo.meter_release.release_rate_for`)."""
    if cfg.meter_mode == "one_per_green":
        return (min(0.0, cfg.release_rate - cfg.release_rate_max),
                max(0.0, cfg.release_rate - cfg.release_rate_min))
    m = curve.monotone()
    return (min(0.0, m.outflow_at(cfg.green_share_max) - q_nominal),
            max(0.0, m.outflow_at(cfg.green_share_min) - q_nominal))


def ramp_floor(curve: GreenShareCurve, cfg: SumoConfig, q_nominal: float, queue: float) -> float:
    """Least U (veh/s) the ramp can deliver with ``queue`` vehicles waiting.

    The rule: the merge passes ``q_open`` = the curve's mainline outflow at green share 0
    (mainline alone, ramp closed) in all, so each ramp vehicle released takes one from the
    mainline. Over the next plan, ``H = max(meter cycle, control period)`` seconds, the
    ramp can release at most its arrivals and its queue, ``r + queue / H`` veh/s (``r``:
    ``[sumo] ramp_demand``), so more ramp green cannot bring the mainline outflow below
    ``q_open - r - queue / H``: U below that minus q* is not deliverable. Capped at 0 (the
    nominal plan is always allowed), so it only bounds U < 0 (more ramp release).
    One per green, by the same rule (U = r_nominal - r): ``r_nominal - r - queue / H``,
    with the nominal cycle 1 / r_nominal for the meter cycle.
    """
    if cfg.meter_mode == "one_per_green":
        horizon = max(1.0 / cfg.release_rate, cfg.control_period)
        return min(0.0, cfg.release_rate - cfg.ramp_demand - queue / horizon)
    q_open = curve.monotone().outflow_at(0.0)
    horizon = max(cfg.meter_cycle, cfg.control_period)
    return min(0.0, q_open - cfg.ramp_demand - queue / horizon - q_nominal)


@dataclass
class ActuationLimits:
    """The ``[actuation]`` limits in SI for one run (see the module docstring).

    ``u_max`` (veh/s, inf: off), ``rate_step`` (veh/s per control period, inf: off), and
    with ``ramp_bound`` the meter's range and the ramp's floor from ``curve`` and ``cfg``.
    """

    u_max: float = INF
    rate_step: float = INF
    ramp_bound: bool = False
    curve: GreenShareCurve | None = None
    cfg: SumoConfig | None = None
    q_nominal: float = 0.0

    @classmethod
    def of(cls, settings: ActuationSettings, q_nominal: float, curve: GreenShareCurve,
           cfg: SumoConfig) -> ActuationLimits:
        """The limits of ``settings`` (0: off) around ``q_nominal`` (veh/s)."""
        return cls(settings.u_max_fraction * q_nominal if settings.u_max_fraction else INF,
                   settings.u_rate_max * cfg.control_period if settings.u_rate_max else INF,
                   settings.ramp_bound, curve, cfg, q_nominal)

    def range(self, queue: float) -> tuple[float, float]:
        """``(lower, upper)`` of U (veh/s) with ``queue`` vehicles on the ramp."""
        lower, upper = -self.u_max, self.u_max
        if self.ramp_bound and self.curve is not None and self.cfg is not None:
            lo, hi = meter_range(self.curve, self.cfg, self.q_nominal)
            lower = max(lower, lo, ramp_floor(self.curve, self.cfg, self.q_nominal, queue))
            upper = min(upper, hi)
        return lower, upper


@dataclass(frozen=True)
class Actuation:
    """One command: the law's U and the U applied (veh/s), the limit flags, the range
    ``[lower, upper]`` (veh/s) in force, and the green share commanded."""

    u_raw: float
    u_applied: float
    saturated: bool
    rate_limited: bool
    lower: float
    upper: float
    green: float


class MeterActuator:
    """Commands ``meter`` with the outflow ``q_nominal + U``, U limited by ``limits``.

    Parameters
    ----------
    meter : MeterLight
        The meter of the open run (fixed cycle: the outflow ``q_nominal + U`` through its
        curve; one per green: the release rate of
        :func:`~arzsumo.sumo.meter_release.release_rate_for`).
    q_nominal : float
        Mainline outflow of the nominal plan, veh/s.
    hold_nominal : bool
        Keep the nominal plan whatever U is (the open loop).
    limits : ActuationLimits, optional
        The ``[actuation]`` limits (default: none).
    """

    def __init__(self, meter: MeterLight, q_nominal: float, hold_nominal: bool,
                 limits: ActuationLimits | None = None) -> None:
        self.meter, self.q_nominal, self.hold_nominal = meter, q_nominal, hold_nominal
        self.limits = limits or ActuationLimits()
        self.u_prev = 0.0

    def apply(self, u: float) -> Actuation:
        """Command U (veh/s), limited; return what was applied and the green share
        commanded (in [0, 1])."""
        if self.hold_nominal:
            return Actuation(u, 0.0, False, False, -INF, INF, self.meter.green_share)
        lower, upper = self.limits.range(self.meter.queue)
        rate_step = self.limits.rate_step
        if self.meter.override():
            # the queue override runs the meter at its largest release whatever is
            # commanded: to the law, a saturation of its actuator (anti-windup sees it)
            lower = upper = self.meter.override_u(self.q_nominal)
            rate_step = INF
        lim = limit_u(u, self.u_prev, lower, upper, rate_step)
        self.u_prev = lim.u_applied
        green = self.meter.command(lim.u_applied, self.q_nominal)
        return Actuation(u, lim.u_applied, lim.saturated, lim.rate_limited, lower, upper,
                         green)
