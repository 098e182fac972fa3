"""SUMO as the closed loop's plant: the simulation, its sensor and its meter, stepped as one.

:meth:`SumoPlant.step` is the one step loop of every run: SUMO advances one step, the
sensor reads it (the only reader of libsumo while SUMO steps) and hands the meter its
reading; the meter sets the light for the next step. The warm-up, the control window
(:meth:`SumoPlant.advance`, one control period) and the drain after the window
(:func:`arzsumo.bridge.drain.drain`) all run through it; the fixed-plan runs of
calibration and the tests too (:func:`arzsumo.sumo.runner.run_fixed_meter`).
"""

from __future__ import annotations

import time
from typing import Any

from arzsumo.estimate.observations import LoopNoise, ProbeNoise
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.disturbance import DisturbanceSchedule, Slowdown
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.meter import MeterLight, MeterState
from arzsumo.sumo.meter_release import make_meter
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.sensor import PeriodMeasurement, SumoSensor
from arzsumo.sumo.simulation import SumoSimulation
from arzsumo.sumo.window import WindowStart


class SumoPlant:
    """An open SUMO run with its sensor and its meter (made once, from ``[sumo]
    meter_mode``: :func:`~arzsumo.sumo.meter_release.make_meter`).

    Parameters
    ----------
    sim : SumoSimulation
        The open run.
    length : float
        Length L of the measured section, m.
    cfg : SumoConfig
        The run's SUMO settings (meter, cells, control period).
    curve : GreenShareCurve
        The fixed-cycle meter's calibrated curve.
    layout, loop_noise, probe_noise, window, measure
        The sensor's (:class:`~arzsumo.sumo.sensor.SumoSensor`).
    """

    def __init__(self, sim: SumoSimulation, length: float, cfg: SumoConfig,
                 curve: GreenShareCurve = DEFAULT_CURVE, *,
                 layout: SensorLayout | None = None, loop_noise: LoopNoise | None = None,
                 probe_noise: ProbeNoise | None = None, window: bool = False,
                 measure: bool = True) -> None:
        self.sim = sim
        self.meter: MeterLight = make_meter(sim.lib, cfg, curve)
        self.sensor = SumoSensor(sim.lib, length, cfg, window=window, layout=layout,
                                 loop_noise=loop_noise, probe_noise=probe_noise,
                                 measure=measure)
        self.timings = {"sumo_step": 0.0, "measure_actuate": 0.0}
        self.disturbance: DisturbanceSchedule | None = None

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
        self.timings["sumo_step"] += s1 - s0
        self.timings["measure_actuate"] += time.perf_counter() - s1
        return got

    def advance(self) -> PeriodMeasurement:
        """Step SUMO to the end of the current control period; its measurement."""
        while True:
            got = self.step()
            if got is not None:
                return got

    def run_period(self) -> tuple[PeriodMeasurement, MeterState]:
        """One control period under the meter's present command: the sensor's
        measurement of it and the meter at its end."""
        m = self.advance()
        return m, self.meter.state()

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
