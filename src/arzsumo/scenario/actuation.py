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
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from arzsumo.errors import ArzsumoError, ScenarioError, require
from arzsumo.tables import Key, in_user_terms, not_allowed, read_keys
from arzsumo.units import VEH_H_PER_VEH_S

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
    lies in the range.
    """

    u_max_fraction: float = 0.0
    u_rate_max: float = 0.0
    ramp_bound: bool = False
    anti_windup: bool = True
    delay_compensation: float = 0.0
    meter_gain: float = 1.0
    hold_plan_in_range: bool = False

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
