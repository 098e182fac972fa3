"""The ``[actuation]`` section: limits between the controller's U and the ramp meter.

Every key, its unit and the field of :class:`ActuationSettings` it sets::

    [actuation]
    u_max_fraction = 0.2          # |U| <= 0.2 q*          (0: off)
    u_rate_max_veh_h_s = 100      # |U_k - U_k-1| <= 100 veh/h per s x control period (0: off)
    ramp_bound = true             # U within what the meter and the ramp can deliver
    anti_windup = true            # controllers with state see the U actually applied
    delay_compensation_s = 12     # PDE laws act on the state predicted 12 s ahead (0: off)
    meter_gain = 2                # PDE laws: the outflow moves 2 veh/h per veh/h of release
    hold_plan_in_range = true     # a held U moves the plan only when the range leaves it
    actuator = "speed_limit"      # PDE laws act on the outlet's speed limit, not the meter
    speed_limit_gain_veh_h_per_kmh = 40   # dq(L)/dv_limit
    speed_limit_min_kmh = 10      # the limit's range ...
    speed_limit_max_kmh = 60
    speed_limit_step_kmh = 1      # ... and its resolution (0: continuous)

Without the table every limit is off and a run is today's: the meter receives the
controller's U unchanged (the meter itself still saturates its green share to
``[sumo] green_share_min .. green_share_max``).

``delay_compensation_s`` is the dead time theta from a command to the section's outflow
(10-14 s measured in SUMO, ``arzsumo study meter-dynamics``): backstepping and the ETC then
evaluate control_law on the scaled Riemann state predicted theta seconds ahead
(:func:`arzsumo.control.predictor.predict_riemann`, with the U applied in the last theta
seconds; :class:`arzsumo.control.compensation.DelayCompensated`). It must be shorter than
L / max |lambda| at the equilibrium (one boundary reflection at most):
:func:`check_delay_horizon`. The limits act in
:func:`arzsumo.bridge.actuator.limit_u`; the ramp bound's rule is in
:func:`arzsumo.bridge.actuator.ramp_range`.

``meter_gain`` is -dq(L)/dr, the change of the section's outflow per change of the ramp
release (about 2 on the default's merge, measured by the premise's actuator staircase):
a PDE law's U is handed to the meter divided by it
(:class:`arzsumo.control.meter_gain.MeterGain`). ``hold_plan_in_range``: while a law
holds its U (between an ETC's events, or a held meter), the plan stays where it is as
long as it lies in the range; it moves only when the range (the ramp bound moves with the
queue) leaves it (:class:`arzsumo.bridge.actuator.MeterActuator`).

``actuator`` names what a PDE law's U drives. ``"meter"`` (the default) is the paper's
ramp meter. ``"speed_limit"`` is mainstream control at the section's outlet: the speed
limit of the edge past the merge (``down``, the bottleneck whose discharge sets q(L)) is
``v_nominal + U / speed_limit_gain`` (:class:`arzsumo.bridge.speed_actuator.SpeedLimitActuator`),
within ``[speed_limit_min, speed_limit_max]`` and rounded to ``speed_limit_step``; the
meter keeps its nominal plan. The boundary input is the same q(L) - q* as the paper's;
only its actuator differs, one whose range is several times the meter's on a stream
where the ramp's share of the flow is small. ALINEA, PI-ALINEA and the held meter
command the ramp meter whatever ``actuator`` says.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from arzsumo.errors import ArzsumoError, ScenarioError, require
from arzsumo.tables import Key, in_user_terms, not_allowed, read_keys
from arzsumo.units import KMH_PER_MS, VEH_H_PER_VEH_S, VEH_KM_PER_VEH_M

#: what a PDE law's U can drive
ACTUATORS = ("meter", "speed_limit")

#: [actuation] key -> ActuationSettings field (SI)
ACTUATION_KEYS: dict[str, Key] = {
    "u_max_fraction": Key("u_max_fraction",
                          allowed="a fraction of q* in [0, 1] (0: no magnitude limit)",
                          doc="abs(U) <= this fraction of q* (the nominal outflow); 0: off"),
    "u_rate_max_veh_h_s": Key("u_rate_max", factor=VEH_H_PER_VEH_S, unit="veh/h/s",
                              allowed="a rate >= 0 veh/h per s (0: no rate limit)",
                              doc="abs(U_k - U_k-1) <= this rate x the control period; 0: off"),
    "ramp_bound": Key("ramp_bound", "bool",
                      doc="U limited to what the meter can deliver (the green-share curve "
                          "between green_share_min and green_share_max) and no more ramp "
                          "release than the ramp's arrivals and queue (docs/sumo.md)"),
    "anti_windup": Key("anti_windup", "bool",
                       doc="controllers with state (ETC trigger, observer) see the U "
                           "actually applied and the limits; false: they are not told"),
    "delay_compensation_s": Key("delay_compensation", unit="s",
                                allowed="a dead time >= 0 s (0: no delay compensation)",
                                doc="PDE laws (backstepping, etc) act on the state predicted "
                                    "this many s ahead with the U already applied; 0: off"),
    "meter_gain": Key("meter_gain", allowed="a gain > 0 (1: one released ramp vehicle "
                                            "takes one mainline slot)",
                      doc="-dq(L)/dr, the section outflow's change per change of ramp "
                          "release; PDE laws ask the meter for U / meter_gain (default 1)"),
    "hold_plan_in_range": Key("hold_plan_in_range", "bool",
                              doc="a held U keeps the meter's plan while the plan lies in "
                                  "the range; false: the plan follows the range's clip "
                                  "at every period (default false)"),
    "actuator": Key("actuator", "string", choices=ACTUATORS,
                    doc="what a PDE law's U drives: the ramp meter, or the speed limit "
                        "of the edge past the merge (default meter)"),
    "speed_limit_gain_veh_h_per_kmh": Key(
        "speed_limit_gain", factor=VEH_KM_PER_VEH_M, unit="veh/h per km/h",
        allowed="a gain > 0 veh/h per km/h",
        doc="dq(L)/dv_limit: the section outflow's change per change of the outlet's "
            "speed limit (actuator = speed_limit)"),
    "speed_limit_min_kmh": Key("speed_limit_min", factor=KMH_PER_MS, unit="km/h",
                               allowed="a speed > 0 km/h, below speed_limit_max_kmh",
                               doc="the outlet's lowest speed limit (actuator = "
                                   "speed_limit)"),
    "speed_limit_max_kmh": Key("speed_limit_max", factor=KMH_PER_MS, unit="km/h",
                               allowed="a speed above speed_limit_min_kmh",
                               doc="the outlet's highest speed limit (actuator = "
                                   "speed_limit)"),
    "speed_limit_step_kmh": Key("speed_limit_step", factor=KMH_PER_MS, unit="km/h",
                                allowed="a step >= 0 km/h (0: continuous)",
                                doc="the speed limit's resolution: each limit a whole "
                                    "number of steps from the nominal (0: continuous)"),
}


@dataclass(frozen=True)
class ActuationSettings:
    """Limits on U between controller and meter (SI).

    ``u_max_fraction`` bounds |U| by that fraction of q* (0: off); ``u_rate_max`` (veh/s
    per s) bounds the change of U between control periods (0: off); ``ramp_bound`` limits
    U to the meter's and the ramp's range; ``anti_windup`` tells the controller the U
    applied (:meth:`arzsumo.control.base.Controller.applied`); ``delay_compensation``
    (s, 0: off) is the dead time theta the PDE laws predict over; ``meter_gain``
    (dimensionless) is -dq(L)/dr; ``hold_plan_in_range`` keeps a held U's plan while it
    lies in the range; ``actuator`` what a PDE law's U drives, with the speed limit's
    ``speed_limit_gain`` (veh/s per m/s = veh/m), range ``speed_limit_min ..
    speed_limit_max`` (m/s) and resolution ``speed_limit_step`` (m/s, 0: continuous).
    """

    u_max_fraction: float = 0.0
    u_rate_max: float = 0.0
    ramp_bound: bool = False
    anti_windup: bool = True
    delay_compensation: float = 0.0
    meter_gain: float = 1.0
    hold_plan_in_range: bool = False
    actuator: str = "meter"
    speed_limit_gain: float = 0.04
    speed_limit_min: float = 10.0 / KMH_PER_MS
    speed_limit_max: float = 60.0 / KMH_PER_MS
    speed_limit_step: float = 0.0

    def __post_init__(self) -> None:
        require(math.isfinite(self.u_max_fraction) and 0.0 <= self.u_max_fraction <= 1.0,
                "u_max_fraction", self.u_max_fraction, "a fraction in [0, 1]", ScenarioError)
        require(math.isfinite(self.u_rate_max) and self.u_rate_max >= 0.0, "u_rate_max",
                self.u_rate_max, "a rate >= 0 veh/s per s", ScenarioError)
        require(math.isfinite(self.delay_compensation) and self.delay_compensation >= 0.0,
                "delay_compensation", self.delay_compensation, "a dead time >= 0 s",
                ScenarioError)
        require(math.isfinite(self.meter_gain) and self.meter_gain > 0.0, "meter_gain",
                self.meter_gain, "a gain > 0", ScenarioError)
        require(self.actuator in ACTUATORS, "actuator", self.actuator,
                f"one of {', '.join(ACTUATORS)}", ScenarioError)
        require(math.isfinite(self.speed_limit_gain) and self.speed_limit_gain > 0.0,
                "speed_limit_gain", self.speed_limit_gain, "a gain > 0 veh/m",
                ScenarioError)
        require(math.isfinite(self.speed_limit_min) and self.speed_limit_min > 0.0,
                "speed_limit_min", self.speed_limit_min, "a speed > 0 m/s", ScenarioError)
        require(math.isfinite(self.speed_limit_max)
                and self.speed_limit_max > self.speed_limit_min, "speed_limit_max",
                self.speed_limit_max, "a speed above speed_limit_min", ScenarioError)
        require(math.isfinite(self.speed_limit_step) and self.speed_limit_step >= 0.0,
                "speed_limit_step", self.speed_limit_step, "a step >= 0 m/s",
                ScenarioError)

    @property
    def active(self) -> bool:
        """True when any limit is on."""
        return self.u_max_fraction > 0 or self.u_rate_max > 0 or self.ramp_bound

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def actuation_section(table: Mapping[str, Any], at: str) -> ActuationSettings:
    """The ActuationSettings of an ``[actuation]`` table (keys already checked); errors
    name the key and the value as written."""
    si = read_keys(table, ACTUATION_KEYS, at)
    try:
        return ActuationSettings(**si)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, table, ACTUATION_KEYS) from None


def delay_horizon(eigenvalues: np.ndarray, length: float) -> float:
    """L / max |lambda| (s): the longest prediction with one boundary reflection at most
    (:func:`arzsumo.control.predictor.predict_riemann`); inf without finite speeds."""
    lam = np.abs(np.asarray(eigenvalues, float))
    return length / float(lam.max()) if np.all(np.isfinite(lam)) and lam.max() > 0 else math.inf


def check_delay_horizon(settings: ActuationSettings, eigenvalues: np.ndarray, length: float,
                        at: str, written_value: Any = None, why: str = "") -> None:
    """Refuse ``delay_compensation_s`` >= L / max |lambda| (``eigenvalues`` in m/s,
    ``length`` in m) with one line naming ``at`` (``file: [actuation]``), the key and the
    value as written; ``why`` names the equilibrium when it is not the scenario's."""
    theta = settings.delay_compensation
    horizon = delay_horizon(eigenvalues, length)
    if theta >= horizon:
        value = theta if written_value is None else written_value
        raise not_allowed(at, "delay_compensation_s", value,
                          f"a dead time in [0, {horizon:.4g}) s, shorter than L / max "
                          f"|lambda| at the {why or 'scenario'} equilibrium (one boundary "
                          "reflection at most)")


def check_speed_limit(settings: ActuationSettings, down_speed: float, slowed_edge: str | None,
                      at: str, table: Mapping[str, Any]) -> None:
    """Refuse a speed-limit actuator whose range leaves out the outlet's own limit
    ``down_speed`` (m/s, the open loop's), or that shares its edge with a slowdown
    (``slowed_edge``: the edge a ``[disturbance]`` slows, None without one); one line
    naming ``at`` (``file: [actuation]``), the key and the value as written."""
    if settings.actuator != "speed_limit":
        return
    if not settings.speed_limit_min <= down_speed <= settings.speed_limit_max:
        key = ("speed_limit_min_kmh" if down_speed < settings.speed_limit_min
               else "speed_limit_max_kmh")
        raise not_allowed(at, key, table.get(key), "a range that holds the outlet's own "
                          f"limit, [sumo] down_speed_kmh = {down_speed * KMH_PER_MS:g}")
    if slowed_edge == "down":
        raise not_allowed(at, "actuator", table.get("actuator"),
                          "meter while [disturbance] slows the edge past the merge, the "
                          "speed limit's own edge")
