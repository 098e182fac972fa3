"""One control period of the closed loop, in one place: sense, estimate, decide, actuate, record.

A detector sample's path: ``SumoSensor.observe`` (every step; the sensor is the only
reader of SUMO) -> ``PeriodMeasurement`` -> ``Estimator.estimate`` (minus the warm-up
reference, :mod:`~arzsumo.bridge.reference`) -> ``MacroState`` -> ``Controller.step`` (told
what was applied for its previous check) -> ``Command`` -> ``MeterActuator.apply`` (the
limits, :mod:`~arzsumo.bridge.actuator`) -> ``MeterLight.set_plan`` -> the light, from the
next cycle on. Each check and the period that followed become one
:class:`~arzsumo.bridge.records.PeriodRecord`; the reference twin's controller checks on
the reference twin, and both twins advance over the period.

The first check is on the warm-up's last measurement (t = 0); no command follows the last
check, at the horizon (no period follows it). :meth:`ClosedLoop.run` is
:meth:`~ClosedLoop.begin`, then per period :meth:`~ClosedLoop.estimate`,
:meth:`~ClosedLoop.decide` and :meth:`~ClosedLoop.advance`; an outside driver
(:mod:`arzsumo.gym`) calls the same stages one period at a time.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from arzsumo.bridge.actuator import Actuation, Actuator
from arzsumo.bridge.estimator import Estimator
from arzsumo.bridge.records import PeriodRecord, Trace, micro_fields
from arzsumo.bridge.reference import ReferenceShift
from arzsumo.bridge.twins import TwinPair
from arzsumo.control.base import Applied, Command, Controller, MacroState
from arzsumo.progress import RunProgress
from arzsumo.sumo.meter import MeterState
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.sensor import PeriodMeasurement


@dataclass(frozen=True)
class Check:
    """One check: its time (s from the start of control), the controller's command, the
    reference twin's U (veh/s) and the wall time of the controller's check (s)."""

    t: float
    command: Command
    u_reference: float
    wall_s: float


class ClosedLoop:
    """The stages of the control window (module docstring), each one object; ``period``:
    the control period (s); ``anti_windup``: tell the controller the range its U was
    limited to; ``shift``: the warm-up reference subtracted from the estimate."""

    def __init__(self, plant: SumoPlant, estimator: Estimator, controller: Controller,
                 actuator: Actuator, twins: TwinPair, period: float,
                 anti_windup: bool = True, shift: ReferenceShift | None = None) -> None:
        self.plant, self.estimator, self.controller = plant, estimator, controller
        self.actuator, self.twins, self.period = actuator, twins, period
        self.anti_windup, self.shift = anti_windup, shift
        self.timings = {"controller": 0.0, "twins": 0.0, "estimator": 0.0}
        # where the window stands (begin, advance): the start's SUMO time (s), the last
        # measurement's time from it (s), what the controller is told at its next check
        self.t0, self.t = 0.0, 0.0
        self.told: Applied | None = None
        self.m: PeriodMeasurement | None = None
        self.trace: Trace | None = None

    def run(self, start: PeriodMeasurement, horizon: float, bar: RunProgress) -> Trace:
        """Control from the measurement ``start`` (t = 0) until ``horizon`` seconds."""
        trace = self.begin(start)
        while True:
            check = self.decide(self.estimate(self.m, self.t), self.told)
            if self.t >= horizon - 1e-9:
                return trace
            self.advance(check)
            bar.update(self.m.t)

    def begin(self, start: PeriodMeasurement) -> Trace:
        """Open the window at the measurement ``start`` (t = 0): a new :attr:`trace`, the
        loop at its first check (:attr:`m` the measurement to estimate from, :attr:`t`
        0 s, :attr:`told` None)."""
        self.t0 = start.t
        self.trace = Trace(start.cells.x, micro_fields(start.cells))
        self.m, self.t, self.told = start, 0.0, None
        return self.trace

    def advance(self, check: Check) -> tuple[Actuation, MeterState]:
        """Actuate the command of ``check``, run one control period in SUMO and record it;
        the loop then stands at the period's end (:attr:`m`, :attr:`t`, :attr:`told`).
        Returns what was applied and the meter at the period's end."""
        act = self.actuator.apply(check.command.u)
        self.told = act.told(self.anti_windup)
        m = self.plant.advance()
        meter = self.plant.meter.state()
        self.m, self.t = m, m.t - self.t0
        self.record(self.trace, self.t, check, act, m, meter)
        return act, meter

    def estimate(self, m: PeriodMeasurement, t: float) -> MacroState:
        """The state the controller acts on at ``t`` (s from the start of control)."""
        e0 = time.perf_counter()
        state = self.estimator.estimate(m, t)
        self.timings["estimator"] += time.perf_counter() - e0
        return state

    def decide(self, state: MacroState, told: Applied | None) -> Check:
        """Check the controller (told what was applied for its last check) and the
        reference twin's controller."""
        c0 = time.perf_counter()
        command = self.controller.step(self.acting_on(state), told)
        c1 = time.perf_counter()
        u_reference = self.twins.check_reference()
        self.timings["controller"] += c1 - c0
        self.timings["twins"] += time.perf_counter() - c1
        return Check(state.t, command, u_reference, c1 - c0)

    def acting_on(self, state: MacroState) -> MacroState:
        """What the controller is handed for the estimate ``state``: minus the warm-up
        reference when the run has one (:mod:`~arzsumo.bridge.reference`)."""
        return self.shift.apply(state) if self.shift else state

    def record(self, trace: Trace, t: float, check: Check, act: Actuation,
               m: PeriodMeasurement, meter: MeterState) -> None:
        """Keep ``check`` with the period that followed, ending at ``t`` (s from the start
        of control); advance the twins over it and keep their fields at its end."""
        w0 = time.perf_counter()
        self.twins.advance(m.cells, t, self.period, check.u_reference)
        self.timings["twins"] += time.perf_counter() - w0
        trace.records.append(PeriodRecord.of(check.t, check.command, act,
                                             check.u_reference, check.wall_s, m, meter))
        trace.t.append(t)
        trace.micro.append(micro_fields(m.cells))
        trace.replay.append(self.twins.replay.sample(trace.x))
        trace.reference.append(self.twins.reference.sample(trace.x))
