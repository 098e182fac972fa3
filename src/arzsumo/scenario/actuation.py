"""The ``[actuation]`` section: limits between the controller's U and the ramp meter.

Without the table every limit is off and the meter receives the controller's U unchanged
(it still saturates its green share to ``[sumo] green_share_min .. green_share_max``). The
limits act in :func:`arzsumo.bridge.actuator.limit_u` (docs/sumo.md, "Actuation limits");
``delay_compensation_s`` must stay below L / max |lambda| (:func:`check_delay_horizon`);
``actuator = "speed_limit"`` hands a PDE law's U to the outlet's speed limit instead of the
meter (docs/sumo.md, "The outlet's speed limit as the actuator"). Keys: docs/scenarios.md.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from arzsumo.errors import ScenarioError, require
from arzsumo.tables import Key, not_allowed
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
    """Limits on U between controller and meter: the fields of :data:`ACTUATION_KEYS` in SI.

    Units: ``u_rate_max`` veh/s per s, ``delay_compensation`` s, ``speed_limit_gain`` veh/m
    (veh/s per m/s), ``speed_limit_*`` m/s; ``u_max_fraction``, ``u_rate_max`` and
    ``delay_compensation`` at 0 are off, ``speed_limit_step`` at 0 is continuous.
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
        def check(name: str, ok: bool, allowed: str) -> None:
            value = getattr(self, name)
            require(math.isfinite(value) and ok, name, value, allowed, ScenarioError)

        check("u_max_fraction", 0.0 <= self.u_max_fraction <= 1.0, "a fraction in [0, 1]")
        check("u_rate_max", self.u_rate_max >= 0.0, "a rate >= 0 veh/s per s")
        check("delay_compensation", self.delay_compensation >= 0.0, "a dead time >= 0 s")
        check("meter_gain", self.meter_gain > 0.0, "a gain > 0")
        require(self.actuator in ACTUATORS, "actuator", self.actuator,
                f"one of {', '.join(ACTUATORS)}", ScenarioError)
        check("speed_limit_gain", self.speed_limit_gain > 0.0, "a gain > 0 veh/m")
        check("speed_limit_min", self.speed_limit_min > 0.0, "a speed > 0 m/s")
        check("speed_limit_max", self.speed_limit_max > self.speed_limit_min,
              "a speed above speed_limit_min")
        check("speed_limit_step", self.speed_limit_step >= 0.0, "a step >= 0 m/s")

    @property
    def active(self) -> bool:
        """True when any limit is on."""
        return self.u_max_fraction > 0 or self.u_rate_max > 0 or self.ramp_bound

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def delay_horizon(eigenvalues: np.ndarray, length: float) -> float:
    """L / max |lambda| (s): the longest prediction with one boundary reflection at most
    (:func:`arzsumo.control.predictor.predict_riemann`); inf without finite speeds."""
    lam = np.abs(np.asarray(eigenvalues, float))
    return length / float(lam.max()) if np.all(np.isfinite(lam)) and lam.max() > 0 else math.inf


def check_delay_horizon(settings: ActuationSettings, eigenvalues: np.ndarray, length: float,
                        at: str, written_value: Any = None, why: str = "") -> None:
    """Refuse ``delay_compensation_s`` >= L / max |lambda| (``eigenvalues`` in m/s,
    ``length`` in m); ``why`` names the equilibrium when it is not the scenario's."""
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
    (``slowed_edge``: the edge a ``[disturbance]`` slows, None without one)."""
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
