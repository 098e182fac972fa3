"""ALINEA (Papageorgiou, Hadj-Salem and Blosseville, 1991): the traffic engineer's baseline.

Local integral feedback on the occupancy o measured downstream of the merge:

    r(k) = r(k-1) + K_R (o_target - o(k)),   r saturated to [r_min, r_max],

with r the ramp metering rate. Our actuator takes a mainline outflow command (the same
actuator as the PDE controllers): the rate is expressed as a green share g = r / r_sat of
the meter, and the command is the mainline outflow the meter's calibrated curve gives at g,
U = q(g) - q_nominal. The usual gain K_R = 70 veh/h per % occupancy becomes
K_R / r_sat per unit occupancy in green share.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from arzsumo.control.base import Controller, MacroState
from arzsumo.errors import ModelError, require


class Alinea(Controller):
    """ALINEA on the green share of the ramp meter.

    Parameters
    ----------
    outflow_of_green : callable
        Mainline outflow (veh/s) at a green share in [0, 1] (the meter's calibrated curve).
    nominal_green : float
        Green share of the nominal plan; U is relative to the outflow there.
    target : float
        Target occupancy o_target (fraction); typically the critical occupancy.
    gain : float, optional
        K_R in veh/s per unit occupancy; default 70 veh/h per % = 7000 veh/h per unit.
    saturation_flow : float, optional
        Ramp flow (veh/s) of an always-green meter, r_sat; default 1800 veh/h.
    green_min, green_max : float
        Saturation of the green share.
    """

    name = "alinea"

    def __init__(self, outflow_of_green: Callable[[float], float], nominal_green: float,
                 target: float, gain: float = 7000.0 / 3600.0,
                 saturation_flow: float = 1800.0 / 3600.0, green_min: float = 0.0,
                 green_max: float = 1.0) -> None:
        super().__init__()
        require(0.0 <= green_min <= nominal_green <= green_max <= 1.0, "nominal_green",
                nominal_green, f"within [green_min, green_max] = [{green_min}, {green_max}]",
                ModelError)
        require(math.isfinite(target) and target > 0, "target", target,
                "an occupancy > 0", ModelError)
        require(gain > 0 and saturation_flow > 0, "gain", gain, "> 0 (and saturation_flow > 0)",
                ModelError)
        self.outflow_of_green = outflow_of_green
        self.nominal_green, self.target = nominal_green, target
        self.gain_green = gain / saturation_flow
        self.green_min, self.green_max = green_min, green_max
        self.q_nominal = outflow_of_green(nominal_green)
        self.green = nominal_green

    def reset(self) -> None:
        super().reset()
        self.green = self.nominal_green

    def decide(self, state: MacroState) -> float:
        occ = state.occupancy_out
        previous = self.green
        if math.isfinite(occ):
            g = previous + self.gain_green * (self.target - occ)
            self.green = min(self.green_max, max(self.green_min, g))
        u = self.outflow_of_green(self.green) - self.q_nominal
        self.log.record(state.t, u, u, self.green != previous, green_share=self.green,
                        occupancy=occ)
        return u
