"""One vehicle per green: the ramp meter at a commanded release rate, as the field runs it.

The command is a release rate r (veh/s) in [``release_rate_min``, ``release_rate_max``],
a cycle of 1 / r in whole SUMO steps, each beginning with a green of ``min_green``
extended until the head vehicle has crossed the stop line, at most ``max_green``; an
outflow command U maps to r = r_nominal - U (:func:`release_rate_for`). The cycle, plan
changes and the queue override: docs/sumo.md, "Meter realisation".
"""

from __future__ import annotations

import math
from types import ModuleType

from arzsumo.errors import ArzsumoError, require
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve, plan_green_steps
from arzsumo.sumo.meter import GREEN, RED, YELLOW, MeterLight, RampMeter


def release_rate_for(u: float, cfg: SumoConfig) -> float:
    """Release rate r = r_nominal - U (veh/s) for the outflow command U (veh/s), before the
    rate bounds: one released ramp vehicle takes one mainline slot at the merge
    (r_nominal: ``cfg.release_rate``)."""
    require(math.isfinite(u), "U", u, "a finite flow in veh/s", ArzsumoError)
    return cfg.release_rate - u


class OnePerGreenMeter(MeterLight):
    """Drives the ramp traffic light of an open libsumo run, one vehicle per green."""

    mode = "one_per_green"

    def __init__(self, lib: ModuleType, cfg: SumoConfig) -> None:
        super().__init__(lib, cfg)
        self.min_green_steps = max(1, round(cfg.min_green / self.dt))
        self.max_green_steps = max(self.min_green_steps, round(cfg.max_green / self.dt))
        self.min_red_steps = round(cfg.min_red / self.dt)
        self.rate = cfg.release_rate         # commanded last, veh/s
        self.cycle_steps = self._cycle(cfg.release_rate)
        self._pending = self.cycle_steps
        self._k = 0                          # steps since the current cycle began
        self._length = self.cycle_steps      # length of the current cycle, steps
        self._green = True                   # the current cycle's green is on
        #: shortest length the current cycle's phases allow (green, clearance, min red)
        self._phases = self.max_green_steps + self.clearance_steps + self.min_red_steps
        self._show(GREEN)

    def _cycle(self, r: float) -> int:
        """Cycle of release rate ``r`` (veh/s), whole steps."""
        return max(1, round(1.0 / (r * self.dt)))

    @property
    def green_share(self) -> float:
        """Minimum green over the running cycle (the plan's green share when the head
        vehicle crosses within the minimum green)."""
        return self.min_green_steps / self.cycle_steps

    @property
    def release_rate(self) -> float | None:
        """Release rate commanded last, veh/s (saturated to the bounds)."""
        return self.rate

    def plan_for(self, u: float, q_nominal: float) -> float:
        """Release rate for U (veh/s; :func:`release_rate_for`; ``q_nominal`` unused)."""
        return release_rate_for(u, self.cfg)

    @property
    def plan_bounds(self) -> tuple[float, float]:
        """``[sumo] release_rate_min_veh_h`` and ``release_rate_max_veh_h``, veh/s."""
        return self.cfg.release_rate_min, self.cfg.release_rate_max

    def set_plan(self, plan: float) -> float:
        """Request release rate ``plan`` (veh/s); return the green share of the requested
        plan (a changed cycle is a plan change)."""
        self._check_plan(plan)
        self.rate = plan
        new = self._cycle(self.rate)
        if new != self._pending:
            self._pending = new
            self.plan_changes += 1
        return self.min_green_steps / self._pending

    def u_range(self, q_nominal: float) -> tuple[float, float]:
        return one_per_green_u_range(self.cfg)

    def ramp_floor(self, queue: float, q_nominal: float) -> float:
        return one_per_green_ramp_floor(self.cfg, queue)

    def override_u(self, q_nominal: float) -> float:
        """U (veh/s) of the override's rate: r_nominal - ``release_rate_max``
        (``q_nominal`` unused, as in :meth:`plan_for`)."""
        return self.cfg.release_rate - self.cfg.release_rate_max

    def _plan(self) -> str:
        fastest = self._cycle(self.cfg.release_rate_max)
        override = self.override()
        if override:      # cut the running cycle to the fastest one its phases allow
            self.override_steps += self.cycle_steps > fastest or self._pending > fastest
            self._length = min(self._length, max(fastest, self._phases))
        self._k += 1
        if self._k >= self._length:
            self.cycle_steps = min(self._pending, fastest) if override else self._pending
            self._k, self._length, self._green = 0, self.cycle_steps, True
            self._phases = self.max_green_steps + self.clearance_steps + self.min_red_steps
            return GREEN
        if self._green:
            released = self.greens[-1].releases if self.greens else 0   # in this green
            done = released > 0 and self._k >= self.min_green_steps
            if done or self._k >= self.max_green_steps:
                self._green = False
                self._phases = self._k + self.clearance_steps + self.min_red_steps
                self._length = max(self.cycle_steps, self._phases)
        return GREEN if self._green else RED


def one_per_green_u_range(cfg: SumoConfig) -> tuple[float, float]:
    """The U (veh/s) one vehicle per green can command: r_nominal - r for r in
    [``release_rate_min``, ``release_rate_max``], widened to include 0."""
    return (min(0.0, cfg.release_rate - cfg.release_rate_max),
            max(0.0, cfg.release_rate - cfg.release_rate_min))


def one_per_green_ramp_floor(cfg: SumoConfig, queue: float) -> float:
    """Least U (veh/s) with ``queue`` vehicles waiting: r_nominal - r - queue / H (``r``:
    ``[sumo] ramp_demand``; H the longer of the nominal cycle 1 / r_nominal and the
    control period), capped at 0 (as
    :func:`~arzsumo.sumo.meter.fixed_cycle_ramp_floor`)."""
    horizon = max(1.0 / cfg.release_rate, cfg.control_period)
    return min(0.0, cfg.release_rate - cfg.ramp_demand - queue / horizon)


def make_meter(lib: ModuleType, cfg: SumoConfig,
               curve: GreenShareCurve = DEFAULT_CURVE) -> RampMeter | OnePerGreenMeter:
    """The meter ``cfg.meter_mode`` names, on the light of an open libsumo run."""
    if cfg.meter_mode == "one_per_green":
        return OnePerGreenMeter(lib, cfg)
    return RampMeter(lib, cfg, curve)


def nominal_phases(cfg: SumoConfig) -> list[tuple[str, int]]:
    """One cycle of the nominal plan (the open loop's) as (state, SUMO steps) phases.

    Green, the clearance yellow, red for the rest, as the meters time them; one per green
    as if the head vehicle crossed within the minimum green. The queue override is left
    out: it depends on the traffic.
    """
    dt = cfg.step_length
    clear = round(cfg.meter_clearance / dt)
    if cfg.meter_mode == "one_per_green":
        green = max(1, round(cfg.min_green / dt))
        cycle = max(max(1, round(1.0 / (cfg.release_rate * dt))),
                    green + clear + round(cfg.min_red / dt))
    else:
        cycle = max(1, round(cfg.meter_cycle / dt))
        green = plan_green_steps(cfg.green_share, cycle, round(cfg.min_green / dt),
                                 round(cfg.min_red / dt) + clear)
    if green in (0, cycle):           # always red or always green: no clearance shown
        return [(GREEN if green else RED, cycle)]
    clear = min(clear, cycle - green)
    phases = [(GREEN, green), (YELLOW, clear), (RED, cycle - green - clear)]
    return [(state, n) for state, n in phases if n > 0]
