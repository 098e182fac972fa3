"""The records every premise gate shares: its thresholds and its result.

:class:`PremiseThresholds` holds every pass/fail threshold of the gates (SI units), each
with its default and the reason for it; :class:`GateResult` is what a gate returns for
one seed. Both are frozen and check themselves on construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from numbers import Real
from typing import Any

import numpy as np

from arzsumo.errors import ArzsumoError, require
from arzsumo.units import kmh_to_ms


class PremiseError(ArzsumoError, ValueError):
    """Data or thresholds a premise gate cannot use (shape, sign, a record too short)."""


def _finite(value: object) -> bool:
    return isinstance(value, Real) and math.isfinite(float(value))


@dataclass(frozen=True)
class PremiseThresholds:
    """Pass/fail thresholds of the premise gates (SI: m, s, m/s, veh/s; ratios 1).

    Attributes
    ----------
    file_speed_gap : float
        Coupled stream: the largest difference of the mean speeds of a class's lateral
        files, m/s (default 10 km/h). The model has one speed per class at (x, t); two
        files 10 km/h apart would need two speed fields. 10 km/h is about a third of the
        paper's equilibrium HV speed (32 km/h) and well above the few km/h that the files'
        mean speeds differ by through sampling alone.
    wave_min_r2 : float
        Waves: least r^2 of the fit lag = a + d / c over the place pairs (default 0.9). A
        wave that travels at one speed gives a lag linear in distance; 0.9 leaves room
        for the integer-sample lags of short distances.
    wave_min_pairs : int
        Waves: fewest distances with a resolved lag for a fit (default 3: a line through
        two points always fits).
    wave_min_corr : float
        Waves: least pair-averaged peak correlation for a distance's lag to count
        (default 0.3; unrelated noise of 600 samples peaks below 0.25).
    model_wave_tolerance : float
        Model: the largest relative gap between |lambda_4| and the measured upstream wave
        speed (default 0.25). The backstepping kernels and the law's convergence time
        scale with L / |lambda_4|; within 25 % the round trip the design assumes is off
        by at most a quarter (a tolerance chosen for the gate, not derived).
    min_amplification : float
        Instability (a): least ratio of the oscillation amplitude at the upstream end to
        that at the downstream end (default 1.0: waves do not decay as they travel
        upstream; the neutral point, the pulse test is the sharper one).
    pulse_decay_fraction : float
        Instability (b): the paired-pulse deviation counts as decayed when its excess over
        the floor falls below this share of its peak excess (default 1/e, one
        e-folding of an exponential decay).
    pulse_round_trips : float
        Instability (b): the window, in round trips L / v + L / |lambda| after the pulse,
        within which a decay means a stable stream (default 2). Within a round trip a
        perturbation is carried out of the section or reflected at its ends; one that
        has not lost most of its size after two is not damped by the open loop on the
        time scale the controllers act on (the paper's convergence time is one).
    gain_range : (float, float)
        Actuator: allowed dq(L) / dr per step direction (default -1.3 to -0.7). The paper's
        input U moves q(L) one to one; a ramp vehicle released displaces about one
        mainline vehicle at the merge when the mainline is at capacity (gain -1). 30 %
        either way is a tolerance chosen for the gate (the laws assume a unit gain; the
        twin is where their tolerance of a gain error can be measured).
    gain_ci_halfwidth : float
        Actuator: the largest half width of the 95 % interval of a direction's per-step
        gains, when it has two steps or more (default 0.3: the range's own half width;
        a wider interval cannot tell a gain in the range from one outside it).
    min_inserted : float
        Operating point: least share of the mainline demand that SUMO inserted (default
        0.98; the rest waits outside the network and is not in the modelled stream).
    seed_share : float
        Over seeds: least share of seeds on which a gate must pass (default 0.8, "most
        seeds": 4 of 5, 8 of 10).
    """

    file_speed_gap: float = float(kmh_to_ms(10.0))
    wave_min_r2: float = 0.9
    wave_min_pairs: int = 3
    wave_min_corr: float = 0.3
    model_wave_tolerance: float = 0.25
    min_amplification: float = 1.0
    pulse_decay_fraction: float = math.exp(-1.0)
    pulse_round_trips: float = 2.0
    gain_range: tuple[float, float] = (-1.3, -0.7)
    gain_ci_halfwidth: float = 0.3
    min_inserted: float = 0.98
    seed_share: float = 0.8

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name not in ("gain_range", "wave_min_pairs"):
                v = getattr(self, f.name)
                require(_finite(v) and v > 0, f.name, v, "a finite number > 0", PremiseError)
        for name in ("wave_min_r2", "wave_min_corr", "pulse_decay_fraction"):
            v = getattr(self, name)
            require(v < 1, name, v, "a number in (0, 1)", PremiseError)
        for name in ("min_inserted", "seed_share"):
            v = getattr(self, name)
            require(v <= 1, name, v, "a number in (0, 1]", PremiseError)
        n = self.wave_min_pairs
        require(isinstance(n, int) and n >= 3, "wave_min_pairs", n, "an integer >= 3",
                PremiseError)
        lo_hi = tuple(self.gain_range)
        require(len(lo_hi) == 2 and all(_finite(v) for v in lo_hi) and lo_hi[0] < lo_hi[1],
                "gain_range", self.gain_range, "two finite numbers, low < high",
                PremiseError)
        object.__setattr__(self, "gain_range", (float(lo_hi[0]), float(lo_hi[1])))


@dataclass(frozen=True)
class GateResult:
    """One gate on one seed.

    Attributes
    ----------
    name : str
        The gate, with its class where it has one (``"coupling[hv]"``).
    value : float
        The measured number the gate decides on, in the unit its gate documents (NaN
        when it could not be measured: the gate then fails).
    threshold : float or (float, float)
        What ``value`` is compared with (a range for the actuator gain).
    passed : bool
        The gate's decision.
    detail : dict
        Everything else the gate measured, JSON-friendly (floats, ints, str, lists).
    """

    name: str
    value: float
    threshold: float | tuple[float, float]
    passed: bool
    detail: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        require(isinstance(self.name, str) and bool(self.name), "name", self.name,
                "a non-empty gate name", PremiseError)
        require(isinstance(self.value, Real), "value", self.value,
                "a number (NaN when unmeasured)", PremiseError)
        require(isinstance(self.passed, bool | np.bool_), "passed", self.passed,
                "True or False", PremiseError)
        object.__setattr__(self, "value", float(self.value))
        object.__setattr__(self, "passed", bool(self.passed))

    def as_dict(self) -> dict[str, Any]:
        """The result as plain Python values (for JSON)."""
        thr = list(self.threshold) if isinstance(self.threshold, tuple) else self.threshold
        return {"name": self.name, "value": self.value, "threshold": thr,
                "passed": self.passed, "detail": dict(self.detail)}
