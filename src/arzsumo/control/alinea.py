"""ALINEA and PI-ALINEA as practitioners run them: local occupancy feedback on the release rate.

ALINEA (Papageorgiou, Hadj-Salem and Blosseville, Transp. Res. Rec. 1320, 1991) and
PI-ALINEA (Wang, Kosmatopoulos, Papageorgiou and Papamichail, IEEE T-ITS 15(5), 2014),
each updated once per its own period T on the period's mean occupancy o(k) of one loop
past the merge nose, r clamped to [r_min, r_max]; K_R and K_I are given at T_ref and
scaled as K(T_ref) T / T_ref. The command is U = r_nominal - r (veh/s). docs/sumo.md,
"Baselines a practitioner would field".

SI throughout: rates veh/s, occupancy a fraction (SUMO's loop occupancy; it can exceed 1
with vehicles side by side under the sublane model), gains veh/s per unit occupancy,
times s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arzsumo.control.base import ConstantControl, Controller, MacroState
from arzsumo.errors import ModelError, ScenarioError, require

#: 70 veh/h per % of occupancy (the field's K_R at a 60 s period), veh/s per unit occupancy
GAIN_70 = 70.0 * 100.0 / 3600.0
#: allowed control periods (s) and loop distances downstream of the merge nose (m)
PERIOD_RANGE = (20.0, 60.0)
DISTANCE_RANGE = (40.0, 300.0)


@dataclass(frozen=True)
class AlineaSettings:
    """Parameters of ALINEA and PI-ALINEA (SI; the ``[alinea]`` table of a scenario).

    ``target`` sits just below the loop's critical occupancy (``arzsumo alinea-target``).
    """

    period: float = 40.0                # T, s, in [20, 60]
    loop_distance: float = 100.0        # m past the merge nose (end of ``merge``), in [40, 300]
    target: float = 0.2                 # o_target, an occupancy fraction > 0
    gain: float = GAIN_70               # K_R at ``gain_period``, veh/s per unit occupancy, > 0
    gain_period: float = 60.0           # T_ref of ``gain`` and ``ki``, s, > 0
    kp: float = 60.0 * 100.0 / 3600.0   # PI-ALINEA's K_P, >= 0 (not scaled with the period)
    ki: float = 5.0 * 100.0 / 3600.0    # PI-ALINEA's K_I at ``gain_period``, >= 0

    def __post_init__(self) -> None:
        def check(ok: bool, name: str, allowed: str) -> None:
            require(ok, name, getattr(self, name), allowed, ScenarioError)

        lo, hi = PERIOD_RANGE
        check(math.isfinite(self.period) and lo <= self.period <= hi, "period",
              f"a period in [{lo:g}, {hi:g}] s")
        lo, hi = DISTANCE_RANGE
        check(math.isfinite(self.loop_distance) and lo <= self.loop_distance <= hi,
              "loop_distance", f"a distance in [{lo:g}, {hi:g}] m downstream of the merge")
        check(math.isfinite(self.target) and 0 < self.target < 10, "target",
              "an occupancy fraction > 0")
        check(math.isfinite(self.gain) and self.gain > 0, "gain", "a gain > 0")
        check(math.isfinite(self.gain_period) and self.gain_period > 0, "gain_period",
              "a period > 0 s")
        check(math.isfinite(self.kp) and self.kp >= 0, "kp", "a gain >= 0")
        check(math.isfinite(self.ki) and self.ki >= 0, "ki", "a gain >= 0")

    def scaled(self, gain: float) -> float:
        """An integral gain given at ``gain_period`` scaled to ``period``:
        K(T) = K(T_ref) T / T_ref (the same integral action per second)."""
        return gain * self.period / self.gain_period


@dataclass(frozen=True)
class ReleaseRates:
    """The meter's release rates, veh/s: nominal (the open loop's, U = 0) and bounds."""

    nominal: float
    low: float
    high: float

    def __post_init__(self) -> None:
        require(0 < self.low <= self.nominal <= self.high, "release_rate", self.nominal,
                f"a rate in [{self.low}, {self.high}] veh/s", ModelError)


def alinea_step(r_prev: float, occupancy: float, target: float, gain: float,
                low: float, high: float) -> float:
    """ALINEA's update r(k) = clamp(r(k-1) + K_R (o_target - o(k))), veh/s."""
    return min(high, max(low, r_prev + gain * (target - occupancy)))


def pi_alinea_step(r_prev: float, occupancy: float, occupancy_prev: float, target: float,
                   kp: float, ki: float, low: float, high: float) -> float:
    """PI-ALINEA's update r(k) = clamp(r(k-1) - K_P (o(k) - o(k-1)) + K_I (o_target -
    o(k))), veh/s."""
    r = r_prev - kp * (occupancy - occupancy_prev) + ki * (target - occupancy)
    return min(high, max(low, r))


class Alinea(Controller):
    """ALINEA on the release rate, updated once per its own period (module docstring).

    ``rates`` gives r(0) (the nominal rate) and the clamp [r_min, r_max], veh/s;
    ``settings.period`` must be a whole multiple of ``check_period``, the closed loop's, s.
    """

    name = "alinea"

    def __init__(self, settings: AlineaSettings, rates: ReleaseRates,
                 check_period: float = 1.0) -> None:
        super().__init__()
        n = round(settings.period / check_period)
        require(n >= 1 and abs(n * check_period - settings.period) < 1e-6, "period",
                settings.period, f"a whole multiple of the control period {check_period:g} s",
                ScenarioError)
        self.settings, self.rates, self.checks_per_update = settings, rates, n
        self.reset()

    def reset(self) -> None:
        super().reset()
        self.rate = self.rates.nominal
        self.occupancy_prev = math.nan     # o(k-1), PI-ALINEA
        self._samples: list[float] = []
        self._checks = 0
        self._range = (-math.inf, math.inf)  # rates the actuator allowed last (anti-windup)

    def update(self, occupancy: float) -> float:
        """One ALINEA update with the period's mean occupancy; the new rate, veh/s."""
        s = self.settings
        lo, hi = self._range
        return alinea_step(self.rate, occupancy, s.target, s.scaled(s.gain),
                           max(self.rates.low, lo), min(self.rates.high, hi))

    def decide(self, state: MacroState) -> float:
        occ = state.occupancy_out
        if math.isfinite(occ):
            self._samples.append(occ)
        self._checks += 1
        previous, mean = self.rate, math.nan
        if self._checks >= self.checks_per_update:
            if self._samples:
                mean = sum(self._samples) / len(self._samples)
                self.rate = self.update(mean)
                self.occupancy_prev = mean
            self._samples, self._checks = [], 0
        u = self.rates.nominal - self.rate
        self.log.record(state.t, u, u, self.rate != previous, release_rate=self.rate,
                        occupancy=occ, occupancy_mean=mean)
        return u

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        """Anti-windup on the actuator's range: U in ``[lower, upper]`` is r in
        ``[r_nominal - upper, r_nominal - lower]``; the next update clamps the state to
        it (not this check: the command is held between updates)."""
        self._range = (self.rates.nominal - upper, self.rates.nominal - lower)


class PiAlinea(Alinea):
    """PI-ALINEA (Wang et al. 2014): ALINEA with a proportional term on the change of the
    period's occupancy; the first update, with no o(k-1), uses o(k-1) = o(k)."""

    name = "pi-alinea"

    def update(self, occupancy: float) -> float:
        s = self.settings
        prev = occupancy if math.isnan(self.occupancy_prev) else self.occupancy_prev
        lo, hi = self._range
        return pi_alinea_step(self.rate, occupancy, prev, s.target, s.kp, s.scaled(s.ki),
                              max(self.rates.low, lo), min(self.rates.high, hi))


class HeldMeter(ConstantControl):
    """The meter held at its least release rate from the start of control:
    U = r_nominal - r_min (veh/s), constant."""

    name = "held"

    def __init__(self, rates: ReleaseRates) -> None:
        super().__init__(rates.nominal - rates.low)
