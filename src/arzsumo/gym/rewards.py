"""Rewards: one control period's record in, a number out, the same on the twin and in SUMO.

``reward=`` is a name of :data:`NAMED`, a mapping of names to weights (their weighted
sum), or any callable taking a :class:`StepRecord` (a callable with a ``reset()`` method
is reset at every episode's start). docs/gym.md, "Rewards".
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from arzsumo.errors import EnvError
from arzsumo.units import ms_to_kmh, s_to_h

#: the time constants of the band-power proxy's exponential means, s (the band's ends)
BAND_S = (60.0, 600.0)
#: the block length of the band-power proxy, m (the summary's wave blocks)
BLOCK_M = 100.0


@dataclass(frozen=True)
class StepRecord:
    """One control period as a reward reads it (SI).

    Attributes
    ----------
    t : float
        End of the period, s from the start of control.
    period : float
        Its length, s.
    x : ndarray (n,)
        Cell centres of ``fields``, m.
    fields : ndarray (4, n)
        The true state (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s): in SUMO the Edie
        cells of the period (speeds NaN in empty cells), on the twin its state at the
        period's end.
    section_veh_h : float
        Vehicle-hours spent on the section during the period.
    u_action, u_applied : float
        The U the agent asked for and the U the actuator applied, veh/s.
    plan_changes : int
        The meter's plan changes in the period.
    queue : float
        The ramp queue at the period's end, veh (0 on the twin).
    saturated, rate_limited : bool
        Which ``[actuation]`` limits acted on the action.
    """

    t: float
    period: float
    x: np.ndarray
    fields: np.ndarray
    section_veh_h: float
    u_action: float
    u_applied: float
    plan_changes: int
    queue: float
    saturated: bool = False
    rate_limited: bool = False


Reward = Callable[[StepRecord], float]


def vehicle_hours(r: StepRecord) -> float:
    """Minus the section's vehicle-hours of the period (an episode's sum: minus SUMO's
    ``summary["TTT"]["total"]`` / 3600, up to the cells' aggregation)."""
    return -r.section_veh_h


def ramp_queue(r: StepRecord) -> float:
    """Minus the ramp queue's vehicle-hours of the period."""
    return -float(s_to_h(r.queue * r.period))


def plan_changes(r: StepRecord) -> float:
    """Minus the period's plan changes."""
    return -float(r.plan_changes)


class BandPower:
    """Minus a per-period proxy of the HV speed's stop-and-go band power, (km/h)^2.

    The HV speed's 100 m block means are filtered by two exponential means of time
    constants 60 s and 600 s (both started at the first period's speeds); the reward is
    minus the mean over blocks of their difference squared. A causal stand-in for the
    summary's ``["section"]["waves"]["h"]["band_power_kmh2"]`` (a periodogram over the
    whole window, periods of 60 to 600 s), zero on a stationary stream; reset per episode.
    """

    def __init__(self) -> None:
        self.fast: np.ndarray | None = None
        self.slow: np.ndarray | None = None

    def reset(self) -> None:
        self.fast = self.slow = None

    def __call__(self, r: StepRecord) -> float:
        dx = float(r.x[1] - r.x[0]) if r.x.size > 1 else BLOCK_M
        k = max(1, round(BLOCK_M / dx))
        n = r.x.size // k * k
        v = np.asarray(r.fields[1, :n], float).reshape(-1, k)
        ok = np.isfinite(v).any(axis=1)
        blocks = np.full(v.shape[0], np.nan)
        blocks[ok] = ms_to_kmh(np.nanmean(v[ok], axis=1))
        if self.fast is None or self.slow is None:
            self.fast, self.slow = blocks.copy(), blocks.copy()
            return 0.0
        for ema, tau in ((self.fast, BAND_S[0]), (self.slow, BAND_S[1])):
            a = 1.0 - np.exp(-r.period / tau)
            fresh = ~np.isfinite(ema) & np.isfinite(blocks)
            ema[fresh] = blocks[fresh]
            upd = np.isfinite(blocks)
            ema[upd] += a * (blocks[upd] - ema[upd])
        d = self.fast - self.slow
        return -float(np.nanmean(d**2)) if np.isfinite(d).any() else 0.0


#: the named rewards: name -> a maker of a fresh reward
NAMED: dict[str, Callable[[], Reward]] = {
    "vehicle-hours": lambda: vehicle_hours,
    "ramp-queue": lambda: ramp_queue,
    "band-power": BandPower,
    "plan-changes": lambda: plan_changes,
}


class Weighted:
    """The weighted sum of named rewards, ``{name: weight}``."""

    def __init__(self, weights: Mapping[str, float]) -> None:
        self.weights = dict(weights)
        self.parts = {name: NAMED[name]() for name in self.weights}

    def reset(self) -> None:
        for part in self.parts.values():
            reset_reward(part)

    def __call__(self, r: StepRecord) -> float:
        return float(sum(w * self.parts[n](r) for n, w in self.weights.items()))


def _refuse(value: Any) -> EnvError:
    allowed = (f"a callable(StepRecord) -> float, one of {', '.join(NAMED)}, or a mapping "
               "of those names to finite weights")
    exc = EnvError(f"reward = {value!r} is not allowed: {allowed}")
    exc.field, exc.value, exc.allowed = "reward", value, allowed
    return exc


def reward_of(value: Any) -> Reward:
    """A fresh reward for ``reward=`` (module docstring); an EnvError names a bad one."""
    if isinstance(value, str):
        if value not in NAMED:
            raise _refuse(value)
        return NAMED[value]()
    if isinstance(value, Mapping):
        ok = value and all(isinstance(k, str) and k in NAMED for k in value) and all(
            isinstance(w, int | float) and not isinstance(w, bool) and np.isfinite(w)
            for w in value.values())
        if not ok:
            raise _refuse(dict(value))
        return Weighted(value)
    if callable(value):
        return value
    raise _refuse(value)


def reset_reward(reward: Reward) -> None:
    """Call ``reward.reset()`` when it has one."""
    reset = getattr(reward, "reset", None)
    if callable(reset):
        reset()
