"""The ramp-meter actuator: commanded mainline outflow -> green share -> signal program.

The controller asks for a mainline outflow q* + U (veh/s). The calibrated curve of
mainline outflow against the meter's green share (:class:`GreenShareCurve`, decreasing:
more ramp green, less mainline outflow) is inverted to a green share g in [0, 1], which
becomes a fixed-cycle program: green for g C seconds, then red, with minimum green and
red times (a shorter green becomes all-red or the minimum green, whichever is nearer; the
same for red). A new timing is a *plan change* and takes effect at the next cycle start;
each switch of the light (green to red or red to green) is a *light change*. The ramp
queue (halted vehicles on ``ramp_up`` plus ramp vehicles waiting to be inserted), read by
the sensor (:mod:`arzsumo.sumo.sensor`) and handed to :meth:`RampMeter.step` every step,
and its maximum are tracked; an optional spillback override forces green while the queue
is at or above ``spillback_queue``. The meter reads nothing from SUMO: it only sets the
light.

The counts (plan and light changes, override steps, queue maximum) run over a *window*:
from the meter's creation until :meth:`RampMeter.start_window`, which returns them and
starts a new window (the co-simulation opens one at the start of control, so the warm-up
is counted apart).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from arzsumo.errors import ArzsumoError, require
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network import METER_TL

GREEN, RED = "G", "r"


@dataclass(frozen=True)
class GreenShareCurve:
    """Mainline outflow (veh/s) measured at green shares (ascending, in [0, 1]).

    Outflows must not increase with the green share (ramp vehicles take capacity).
    """

    green_share: tuple[float, ...]
    outflow: tuple[float, ...]

    def __post_init__(self) -> None:
        g, q = np.asarray(self.green_share, float), np.asarray(self.outflow, float)
        require(g.size >= 2 and g.size == q.size, "green_share", self.green_share,
                "at least two points, as many as outflow values", ArzsumoError)
        require(bool(np.all(np.diff(g) > 0)) and g[0] >= 0 and g[-1] <= 1, "green_share",
                self.green_share, "strictly increasing values in [0, 1]", ArzsumoError)
        require(bool(np.all(q > 0)), "outflow", self.outflow, "flows greater than 0 veh/s",
                ArzsumoError)

    def monotone(self) -> GreenShareCurve:
        """The curve made non-increasing (running minimum), for a unique inverse."""
        q = np.minimum.accumulate(np.asarray(self.outflow, float))
        return GreenShareCurve(self.green_share, tuple(float(v) for v in q))

    def outflow_at(self, g: float) -> float:
        """Mainline outflow (veh/s) at green share ``g`` (linear interpolation)."""
        return float(np.interp(g, self.green_share, self.outflow))

    def green_share_for(self, q: float) -> float:
        """Green share giving mainline outflow ``q`` (veh/s), saturated at the curve's ends."""
        m = self.monotone()
        g, out = np.asarray(m.green_share), np.asarray(m.outflow)
        return float(np.interp(q, out[::-1], g[::-1]))


#: Mainline outflow against green share on the default network, 6 s cycle, medium demand
#: (4104 HV/h + 1560 AV/h, ramp 1200 veh/h, seed 42, 450 s, mean after 150 s), as written
#: by ``arzsumo calibrate`` to ``meter_curve.toml`` (load others with
#: :func:`arzsumo.sumo.calibration_io.load_green_share_curve`).
DEFAULT_CURVE = GreenShareCurve((0.0, 0.25, 0.5, 0.75, 1.0),
                                (5664 / 3600, 4512 / 3600, 4464 / 3600, 3300 / 3600,
                                 3240 / 3600))


def plan_green_steps(g: float, cycle: int, min_green: int, min_red: int) -> int:
    """Green steps per cycle of ``cycle`` steps for green share ``g`` in [0, 1].

    A green shorter than ``min_green`` steps becomes 0 (all red) or ``min_green``,
    whichever is nearer; a red shorter than ``min_red`` becomes 0 (all green) or
    ``min_red``. So g = 0 is always red and g = 1 always green.
    """
    require(math.isfinite(g) and 0.0 <= g <= 1.0, "green_share", g, "a number in [0, 1]",
            ArzsumoError)
    green = round(g * cycle)
    if 0 < green < min_green:
        green = 0 if green < min_green / 2 else min_green
    if 0 < cycle - green < min_red:
        green = cycle if cycle - green < min_red / 2 else cycle - min_red
    return green


class RampMeter:
    """Drives the ramp traffic light of an open libsumo run.

    Parameters
    ----------
    lib : module
        The libsumo module of the open run.
    cfg : SumoConfig
        Cycle, minimum green and red, nominal green share, spillback threshold, step.
    curve : GreenShareCurve
        Mainline outflow against green share, inverted by :meth:`command_outflow`.
    """

    def __init__(self, lib: ModuleType, cfg: SumoConfig,
                 curve: GreenShareCurve = DEFAULT_CURVE, tl_id: str = METER_TL) -> None:
        self.lib, self.cfg, self.curve, self.tl_id = lib, cfg, curve, tl_id
        self.dt = cfg.step_length
        self.cycle_steps = max(1, round(cfg.meter_cycle / self.dt))
        self.plan_changes = self.light_changes = self.override_steps = 0
        self.queue = self.max_queue = 0
        self._k = 0                       # steps since the current cycle began
        self.green_steps = self._timing(cfg.green_share)
        self._pending = self.green_steps
        self.light = GREEN if self.green_steps > 0 else RED
        self._set(self.light)

    # -- timing --------------------------------------------------------------------------
    def _timing(self, g: float) -> int:
        return plan_green_steps(g, self.cycle_steps, round(self.cfg.min_green / self.dt),
                           round(self.cfg.min_red / self.dt))

    @property
    def green_share(self) -> float:
        """Green share of the running plan."""
        return self.green_steps / self.cycle_steps

    def set_green_share(self, g: float) -> bool:
        """Request green share ``g``; return True when this is a plan change."""
        new = self._timing(g)
        if new == self._pending:
            return False
        self._pending = new
        self.plan_changes += 1
        return True

    def command_outflow(self, q: float) -> float:
        """Request mainline outflow ``q`` (veh/s) = q* + U; return the green share chosen.

        The green share is saturated to [cfg.green_share_min, cfg.green_share_max].
        """
        require(math.isfinite(q), "outflow", q, "a finite flow in veh/s", ArzsumoError)
        g = min(self.cfg.green_share_max,
                max(self.cfg.green_share_min, self.curve.green_share_for(q)))
        self.set_green_share(g)
        return self._pending / self.cycle_steps

    # -- per-step actuation --------------------------------------------------------------
    def _set(self, state: str) -> None:
        self.lib.trafficlight.setRedYellowGreenState(self.tl_id, state)

    def step(self, queue: int) -> str:
        """Call once after every SUMO step with the ramp queue the sensor read (vehicles,
        :func:`arzsumo.sumo.sensor.ramp_queue`): update cycle and light; return the light."""
        self.queue = queue
        self.max_queue = max(self.max_queue, self.queue)
        self._k += 1
        if self._k >= self.cycle_steps:
            self._k = 0
            self.green_steps = self._pending
        light = GREEN if self._k < self.green_steps else RED
        if self.cfg.spillback_queue and self.queue >= self.cfg.spillback_queue:
            self.override_steps += light == RED
            light = GREEN
        if light != self.light:
            self._set(light)
            self.light = light
            self.light_changes += 1
        return light

    def start_window(self) -> dict[str, float]:
        """Close the current counting window: return its :meth:`summary`, then count anew.

        Plan and light changes and override steps restart from 0; the queue maximum
        restarts from the next :meth:`step` (the light, the cycle and the pending plan
        carry on unchanged).
        """
        closed = self.summary()
        self.plan_changes = self.light_changes = self.override_steps = 0
        self.max_queue = 0
        return closed

    def summary(self) -> dict[str, float]:
        """Counts of the current window (see :meth:`start_window`): plan and light
        changes, queue maximum (veh), override steps; the last queue and green share."""
        return {"plan_changes": self.plan_changes, "light_changes": self.light_changes,
                "max_queue": self.max_queue, "queue": self.queue,
                "override_steps": self.override_steps, "green_share": self.green_share}
