"""The ramp-meter actuator: commanded mainline outflow -> green share -> signal program.

:class:`RampMeter`, the fixed cycle, inverts the calibrated outflow-against-green-share
curve (:class:`~arzsumo.sumo.green_share.GreenShareCurve`) to a green share g: green for
g C seconds, then red. :class:`MeterLight` holds what both realisations share (light,
clearance yellow, queue override, counts over a window: docs/sumo.md, "Ramp meter" and
"Meter realisation"); the other is :class:`arzsumo.sumo.meter_release.OnePerGreenMeter`,
and :func:`arzsumo.sumo.meter_release.make_meter` builds the one ``[sumo] meter_mode`` names.

The meter reads nothing from SUMO: every step the sensor hands it a :class:`MeterReading`
(the ramp queue and the stop line's releases). Each realisation maps an outflow command U
to its own plan variable and states the plan's bounds and the U it can realise; the
actuator (:mod:`arzsumo.bridge.actuator`) saturates in one place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any, NamedTuple

from arzsumo.errors import ArzsumoError, require
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import (
    DEFAULT_CURVE,
    GreenShareCurve,
    fixed_cycle_ramp_floor,
    fixed_cycle_u_range,
    plan_green_steps,
)
from arzsumo.sumo.network import METER_TL

GREEN, YELLOW, RED = "G", "y", "r"
#: the queue override, on above the ramp's storage, stays on until the queue is back at this
#: share of the storage (rounded down)
OVERRIDE_OFF = 0.8


class MeterReading(NamedTuple):
    """One step's reading for the meter: the ramp queue (vehicles) and the vehicles that
    crossed the stop line in the step."""

    queue: int
    released: int


class MeterState(NamedTuple):
    """The meter at the end of a control period: the running green share, light and plan
    changes of the window so far (counts), the ramp queue and its maximum so far (veh),
    and whether the queue override is on."""

    green_share: float
    light_changes: int
    plan_changes: int
    queue: int
    max_queue: int
    override: bool


@dataclass
class GreenRecord:
    """One green interval, from a green's start to the next green's start (steps)."""

    start: int           # SUMO steps since the start when the green began
    queue: int           # ramp queue then, veh
    releases: int = 0    # vehicles that crossed the stop line in the interval
    green: int = 0       # steps shown green
    length: int = 0      # steps so far (the whole interval once the next green began)


class MeterLight:
    """The light, its clearance and the counts shared by both meter realisations.

    Subclasses decide every step whether the plan wants green or red (:meth:`_plan`).
    """

    mode = ""

    def __init__(self, lib: ModuleType, cfg: SumoConfig) -> None:
        self.lib, self.cfg = lib, cfg
        self.tl_id = METER_TL if cfg.layout is None else cfg.layout.meter_tl  # a user's light
        self.dt = cfg.step_length
        self.clearance_steps = round(cfg.meter_clearance / self.dt)
        self.plan_changes = self.light_changes = self.override_steps = 0
        self.queue = self.max_queue = 0
        self.draining = False                 # handed to the drain policy (:meth:`drain`)
        self.override_on_steps = 0            # steps the queue override was on
        self._overriding = False
        self.releases = 0
        self.greens: list[GreenRecord] = []   # every green interval since SUMO started
        self._window_greens = 0               # index of the window's first green
        self._steps = 0                       # steps since SUMO started
        self._yellow_left = 0
        self.light = ""

    def _plan(self) -> str:
        """GREEN or RED wanted by the plan at this step (called once per step)."""
        raise NotImplementedError

    def plan_for(self, u: float, q_nominal: float) -> float:
        """The plan variable (green share; release rate, veh/s) that realises the outflow
        deviation U (veh/s) from ``q_nominal`` (veh/s), before the plan's bounds."""
        raise NotImplementedError

    @property
    def plan_bounds(self) -> tuple[float, float]:
        """Least and largest plan variable the meter may run (:meth:`plan_for`'s unit)."""
        raise NotImplementedError

    def set_plan(self, plan: float) -> float:
        """Request the plan variable ``plan`` (within :attr:`plan_bounds`); a new timing is
        a plan change from the next cycle on. Returns the green share of the request."""
        raise NotImplementedError

    def u_range(self, q_nominal: float) -> tuple[float, float]:
        """The U (veh/s) the meter can realise around ``q_nominal`` (veh/s), widened to
        include 0 (the nominal plan is always allowed)."""
        raise NotImplementedError

    def ramp_floor(self, queue: float, q_nominal: float) -> float:
        """Least U (veh/s) the ramp can deliver with ``queue`` vehicles waiting."""
        raise NotImplementedError

    def _check_plan(self, plan: float) -> None:
        lo, hi = self.plan_bounds
        require(math.isfinite(plan) and lo <= plan <= hi, "plan", plan,
                f"a value in [{lo:.6g}, {hi:.6g}] (saturate in the actuator)", ArzsumoError)

    def _set(self, state: str) -> None:
        if self.cfg.layout is not None:   # the ramp's links of the user's light
            state = self.cfg.layout.signal(state)
        self.lib.trafficlight.setRedYellowGreenState(self.tl_id, state)

    def _show(self, wanted: str) -> None:
        """Show ``wanted``, with the clearance yellow before a red; count light changes."""
        state = wanted
        if wanted == RED and self.clearance_steps:
            if self.light == GREEN:
                self._yellow_left, state = self.clearance_steps, YELLOW
            elif self.light == YELLOW:
                self._yellow_left -= 1
                state = YELLOW if self._yellow_left > 0 else RED
        if state == self.light:
            return
        if (state == GREEN) != (self.light == GREEN) and self.light:
            self.light_changes += 1
        if state == GREEN:
            self.greens.append(GreenRecord(self._steps, self.queue))
        self._set(state)
        self.light = state

    def step(self, reading: MeterReading) -> str:
        """Call once after every SUMO step with the sensor's reading: update the override,
        the plan and the light; return the light."""
        queue, released = reading
        self.queue = queue
        self.max_queue = max(self.max_queue, queue)
        self._update_override()
        self._steps += 1
        self.releases += released
        if self.greens:
            g = self.greens[-1]
            g.releases += released
            g.length = self._steps - g.start
            g.green += self.light == GREEN
        self._show(self._plan())
        self.override_on_steps += self.override() and not self.draining
        return self.light

    def state(self) -> MeterState:
        """The meter now (:class:`MeterState`)."""
        return MeterState(self.green_share, self.light_changes, self.plan_changes,
                          self.queue, self.max_queue, self.override())

    def override(self) -> bool:
        """Whether the queue override is on: from the step the queue exceeds
        ``cfg.ramp_storage`` (> 0) until it is back at :data:`OVERRIDE_OFF` of it, or the
        meter is draining."""
        return self.draining or self._overriding

    def _update_override(self) -> None:
        # hysteresis: switched on and off at one threshold the override flickers with the
        # halted count (a released queue starts moving, is no longer halted, the light
        # turns red, the queue halts again), every step
        storage = self.cfg.ramp_storage
        if storage <= 0:
            self._overriding = False
        elif self.queue > storage:
            self._overriding = True
        elif self.queue <= math.floor(OVERRIDE_OFF * storage):
            self._overriding = False

    def override_u(self, q_nominal: float) -> float:
        """The U (veh/s) the override realises, relative to ``q_nominal`` (veh/s)."""
        raise NotImplementedError

    def drain(self) -> None:
        """Hand the meter to the drain policy for the rest of the run: the queue override
        held on, whatever was commanded (every controller's queue discharged alike)."""
        self.draining = True

    def start_window(self) -> dict[str, Any]:
        """Close the current counting window: return its :meth:`summary`, then count anew.

        The queue maximum restarts from the next :meth:`step`; the light, the cycle and
        the pending plan carry on.
        """
        closed = self.summary()
        self.plan_changes = self.light_changes = self.override_steps = self.releases = 0
        self.max_queue = self.override_on_steps = 0
        self._window_greens = len(self.greens)
        return closed

    @property
    def green_share(self) -> float:
        """Green share of the running plan."""
        raise NotImplementedError

    def summary(self) -> dict[str, Any]:
        """Counts of the current window (see :meth:`start_window`) and the meter's settings:
        the ``meter`` block of summary.json (docs/outputs.md)."""
        greens = self.greens[self._window_greens:]
        return {"plan_changes": self.plan_changes, "light_changes": self.light_changes,
                "max_queue": self.max_queue, "queue": self.queue,
                "override_steps": self.override_steps,
                "override_s": self.override_on_steps * self.dt,
                "green_share": self.green_share,
                "mode": self.mode, "clearance_s": self.cfg.meter_clearance,
                "releases": self.releases, "greens": len(greens),
                "releases_per_green_max": max((g.releases for g in greens), default=0),
                "release_rate": self.release_rate}

    @property
    def release_rate(self) -> float | None:
        """Release rate commanded last, veh/s (None: the meter runs a green share)."""
        return None


class RampMeter(MeterLight):
    """Drives the ramp traffic light of an open libsumo run at a fixed cycle.

    ``curve``: mainline outflow against green share, inverted by :meth:`plan_for`.
    """

    mode = "fixed_cycle"

    def __init__(self, lib: ModuleType, cfg: SumoConfig,
                 curve: GreenShareCurve = DEFAULT_CURVE) -> None:
        super().__init__(lib, cfg)
        self.curve = curve
        self.cycle_steps = max(1, round(cfg.meter_cycle / self.dt))
        self._k = 0                       # steps since the current cycle began
        self.green_steps = self._timing(cfg.green_share)
        self._pending = self.green_steps
        self._show(GREEN if self.green_steps > 0 else RED)

    # -- timing --------------------------------------------------------------------------
    def _timing(self, g: float) -> int:
        """Green steps for share ``g``; the red holds the clearance and the minimum red."""
        return plan_green_steps(g, self.cycle_steps, round(self.cfg.min_green / self.dt),
                                round(self.cfg.min_red / self.dt) + self.clearance_steps)

    @property
    def green_share(self) -> float:
        """Green share of the running plan."""
        return self.green_steps / self.cycle_steps

    def override_u(self, q_nominal: float) -> float:
        """U (veh/s) of the override's green (green share 1 on the curve) from
        ``q_nominal`` (veh/s)."""
        return self.curve.monotone().outflow_at(1.0) - q_nominal

    def set_green_share(self, g: float) -> bool:
        """Request green share ``g``; return True when this is a plan change."""
        new = self._timing(g)
        if new == self._pending:
            return False
        self._pending = new
        self.plan_changes += 1
        return True

    def plan_for(self, u: float, q_nominal: float) -> float:
        """Green share whose curve outflow is ``q_nominal + u`` (veh/s; the curve's ends
        outside it)."""
        q = q_nominal + u
        require(math.isfinite(q), "outflow", q, "a finite flow in veh/s", ArzsumoError)
        return self.curve.green_share_for(q)

    @property
    def plan_bounds(self) -> tuple[float, float]:
        """``[sumo] green_share_min`` and ``green_share_max``."""
        return self.cfg.green_share_min, self.cfg.green_share_max

    def set_plan(self, plan: float) -> float:
        """Request the green share ``plan``; return the green share of the timing chosen."""
        self._check_plan(plan)
        self.set_green_share(plan)
        return self._pending / self.cycle_steps

    def u_range(self, q_nominal: float) -> tuple[float, float]:
        return fixed_cycle_u_range(self.curve, self.cfg, q_nominal)

    def ramp_floor(self, queue: float, q_nominal: float) -> float:
        return fixed_cycle_ramp_floor(self.curve, self.cfg, q_nominal, queue)

    # -- per-step plan -------------------------------------------------------------------
    def _plan(self) -> str:
        self._k += 1
        if self._k >= self.cycle_steps:
            self._k = 0
            self.green_steps = self._pending
        light = GREEN if self._k < self.green_steps else RED
        if self.override():
            self.override_steps += light == RED
            light = GREEN
        return light
