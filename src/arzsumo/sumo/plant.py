"""SUMO as the closed loop's plant: the simulation, its sensor and its meter, stepped as one.

:meth:`SumoPlant.step` is the one step loop of every run: SUMO advances one step, the
sensor reads it and hands the meter its reading; the meter sets the light for the next
step. The warm-up, the control window (:meth:`SumoPlant.advance`) and the drain
(:func:`arzsumo.bridge.drain.drain`) run through it. :meth:`SumoPlant.run_open_loop` is
the one open-loop driver (the warm-up, calibration's fixed-plan runs, the loop curve and
the open-loop studies): control periods under a schedule of plans, a hook called with
each period's :class:`~arzsumo.sumo.period_reads.OpenLoopPeriod`; none of them holds the
open run's module.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

from arzsumo.estimate.observations import LoopNoise, ProbeNoise
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.disturbance import DisturbanceSchedule, Slowdown
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.meter import MeterLight, RampMeter
from arzsumo.sumo.meter_release import make_meter
from arzsumo.sumo.network import APPROACH, approach_edges
from arzsumo.sumo.period_reads import OpenLoopEnd, OpenLoopPeriod, OpenLoopReads, PeriodReader
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.sensor import PeriodMeasurement, SumoSensor
from arzsumo.sumo.simulation import SumoSimulation
from arzsumo.sumo.speed_limit import OutletSpeedLimit
from arzsumo.sumo.window import WindowStart

#: an open-loop run that reads the sensor only
NOTHING_MORE = OpenLoopReads()


class SumoPlant:
    """An open SUMO run with its sensor and its meter (made once, from ``[sumo]
    meter_mode``: :func:`~arzsumo.sumo.meter_release.make_meter`).

    ``length``: L of the measured section, m; ``curve``: the fixed-cycle meter's calibrated
    curve; ``layout``, ``loop_noise``, ``probe_noise``, ``window``, ``measure``: the
    sensor's (:class:`~arzsumo.sumo.sensor.SumoSensor`).
    """

    def __init__(self, sim: SumoSimulation, length: float, cfg: SumoConfig,
                 curve: GreenShareCurve = DEFAULT_CURVE, *,
                 layout: SensorLayout | None = None, loop_noise: LoopNoise | None = None,
                 probe_noise: ProbeNoise | None = None, window: bool = False,
                 measure: bool = True) -> None:
        self.sim, self.cfg = sim, cfg
        self.meter: MeterLight = make_meter(sim.lib, cfg, curve)
        self.sensor = SumoSensor(sim.lib, length, cfg, window=window, layout=layout,
                                 loop_noise=loop_noise, probe_noise=probe_noise,
                                 measure=measure)
        self.timings = {"sumo_step": 0.0, "measure_actuate": 0.0}
        self.disturbance: DisturbanceSchedule | None = None
        #: SUMO steps through :meth:`step` (the sensor's, whose periods they count)
        self.steps = 0

    def disturb(self, disturbance: Slowdown, t0: float) -> None:
        """Schedule ``disturbance``, its times counted from ``t0`` (SUMO time, s): the
        start of control (:mod:`arzsumo.sumo.disturbance`). Nothing when it is none."""
        if disturbance.active:
            self.disturbance = DisturbanceSchedule(self.sim.lib, disturbance, t0)
            self.disturbance.due(self.sim.time)    # a start at 0 acts on the first step

    def step(self) -> PeriodMeasurement | None:
        """One SUMO step, read and acted on; the period's measurement when one ends."""
        s0 = time.perf_counter()
        t = self.sim.step()
        s1 = time.perf_counter()
        if self.disturbance is not None:
            self.disturbance.due(t)
        reading, got = self.sensor.observe(t, self.sim.pending)
        self.meter.step(reading)
        self.steps += 1
        self.timings["sumo_step"] += s1 - s0
        self.timings["measure_actuate"] += time.perf_counter() - s1
        return got

    def advance(self) -> PeriodMeasurement:
        """Step SUMO to the end of the current control period; its measurement."""
        while True:
            got = self.step()
            if got is not None:
                return got

    def run_open_loop(self, periods: int | None = None,
                      on_period: Callable[[OpenLoopPeriod], None] | None = None, *,
                      until: float | None = None, plans: Sequence[tuple[float, float]] = (),
                      reads: OpenLoopReads = NOTHING_MORE,
                      green_shares: bool = False) -> OpenLoopEnd:
        """Step the open loop from a period's boundary: ``periods`` control periods, or
        until SUMO time ``until`` (s; the last period may be cut short); ``on_period`` is
        called at each period's end with its :class:`OpenLoopPeriod`.

        ``plans``: the schedule, (t, plan) sets the meter's plan (``set_plan``: a green
        share or a release rate, veh/s) before the step that starts at SUMO time t (s; a t
        already passed never runs); ``reads``: what to read besides the sensor;
        ``green_shares``: the plans are green shares of the fixed-cycle meter, run as they
        are, past ``[sumo] green_share_min`` and ``green_share_max``. Returns the periods
        run and what ``reads`` asked for at the end.
        """
        if (periods is None) == (until is None):
            raise ValueError("run_open_loop needs periods or until, one of the two")
        per = self.cfg.steps_per_period
        if self.steps % per:
            raise ValueError(f"run_open_loop starts at a period's boundary; the plant is "
                             f"{self.steps % per} steps into a period")
        if green_shares and not isinstance(self.meter, RampMeter):
            raise ValueError("green_shares needs the fixed-cycle meter")
        reader = PeriodReader(self.sim.lib, reads, self.sensor.mainline,
                              self.cfg.step_length, per)
        schedule = sorted(plans, key=lambda p: p[0])
        k = due = 0
        plan: float | None = None
        while (self.sim.time < until - 1e-9) if until is not None else (k < periods):
            due, plan = self._set_due(schedule, due, plan, green_shares)
            got = self.step()
            t = self.sim.time
            reader.step(t)
            if self.steps % per:
                continue
            if got is None and self.sensor.measure:
                raise RuntimeError(f"the sensor's period did not end at t = {t:g} s")
            vehicles, passed, loop = reader.period(t)
            if on_period is not None:
                on_period(OpenLoopPeriod(k, t, got, self.meter.state(), self.meter.releases,
                                         plan, vehicles, passed, loop))
            k += 1
        approach = approach_edges(self.cfg.approach_length, self.cfg.approach_piece)
        return reader.end(k, self.cfg.approach_length, self.sensor.queue, approach or (APPROACH,))

    def _set_due(self, schedule: Sequence[tuple[float, float]], due: int,
                 plan: float | None, green_shares: bool) -> tuple[int, float | None]:
        """Set the plans of ``schedule`` from index ``due`` on that start now (within half
        a step); the next index and the plan requested last."""
        now, tol = self.sim.time, self.cfg.step_length / 2
        while due < len(schedule) and schedule[due][0] <= now - tol:
            due += 1                         # passed: it never runs
        while due < len(schedule) and abs(schedule[due][0] - now) < tol:
            plan = schedule[due][1]
            if green_shares and isinstance(self.meter, RampMeter):   # checked: it is
                self.meter.set_green_share(plan)
            else:
                self.meter.set_plan(plan)
            due += 1
        return due, plan

    def outlet_speed_limit(self) -> OutletSpeedLimit:
        """The speed limit of the edge past the merge, as an actuator."""
        return OutletSpeedLimit(self.sim.lib)

    def expected(self) -> int:
        """Vehicles on the network or still to come (SUMO's ``getMinExpectedNumber``)."""
        return int(self.sim.lib.simulation.getMinExpectedNumber())

    def start_window(self, t: float) -> tuple[dict[str, Any], WindowStart]:
        """Open the control window at ``t`` (s): the meter's and the stop line's counts
        since the start (they count anew from now) and the system's state now."""
        counts = {**self.meter.start_window(), **self.sensor.stop_line.start_window()}
        return counts, self.sensor.start_window(t)

    def meter_summary(self) -> dict[str, Any]:
        """The meter's and the stop line's counts of the current window."""
        return {**self.meter.summary(), **self.sensor.stop_line.summary()}

    def end_window(self) -> None:
        """Close the control window now and hand the meter to the drain policy."""
        self.sensor.end_window(self.sim.time)
        self.meter.drain()
