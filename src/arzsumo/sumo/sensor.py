"""The sensing stage of the closed loop: every libsumo read of a control period.

One :class:`SumoSensor` per run. After each SUMO step :meth:`SumoSensor.observe` reads the
vehicles on ``main`` (:class:`~arzsumo.sumo.measure.MainlineSensor`), the E1 loop on
``down`` (ALINEA's, :class:`~arzsumo.sumo.loops.DownstreamLoop`), the meter's
:class:`~arzsumo.sumo.meter.MeterReading` (from the stop line's detector,
:class:`StopLine`, which also counts the safety events at the meter: docs/sumo.md, "Meter
realisation") and the stations and AV probes of its
:class:`~arzsumo.sumo.sensing.SensorLayout`; fuel and CO2 before the control window and
in the drain after it, the speed moments and lateral offsets in it. A complete control
period gives one :class:`PeriodMeasurement`. Nothing else in the closed loop reads SUMO
while it steps (an open-loop study's further reads: :mod:`arzsumo.sumo.period_reads`);
the meter only writes the traffic light.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from arzsumo.estimate.observations import (
    LoopNoise,
    LoopObservation,
    ProbeNoise,
    ProbeObservation,
)
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.lateral import LateralSampler
from arzsumo.sumo.layout import VehicleClasses
from arzsumo.sumo.loops import DownstreamLoop, LoopSensor, downstream_ids
from arzsumo.sumo.measure import CellData, MainlineSensor
from arzsumo.sumo.meter import MeterReading
from arzsumo.sumo.network import RAMP_UP
from arzsumo.sumo.probes import AvProbes
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.window import (
    EmissionsLedger,
    WindowEnd,
    WindowStart,
    finish_window,
    window_end,
)
from arzsumo.units import ms_to_kmh

#: vehicles at the head of the ramp whose braking the stop-line detector watches
HEAD_VEHICLES = 3
#: braking beyond a vehicle type's ``decel`` by more than this counts as emergency braking
#: at the meter, m/s^2 (SUMO's own count is network-wide)
BRAKING_MARGIN = 0.1


def ramp_queue(lib: ModuleType, pending: Sequence[str] | None = None, edge: str = RAMP_UP,
               is_ramp: Callable[[str], bool] | None = None) -> int:
    """Halted vehicles on ``edge`` (``ramp_up``) plus ramp vehicles still waiting to be
    inserted (``pending``: the ids SUMO holds back this step, read here when not given;
    ``is_ramp``: which are ramp vehicles, by default ids starting with ``ramp``)."""
    if pending is None:
        pending = lib.simulation.getPendingVehicles()
    ramp = is_ramp or (lambda v: v.startswith("ramp"))
    return int(lib.edge.getLastStepHaltingNumber(edge)) + sum(1 for v in pending if ramp(v))


class StopLine:
    """The detector at the stop line of ``ramp_up`` (libsumo, read every step): a vehicle
    is *released* when its front leaves ``ramp_up``; an emergency braking episode is
    counted once per vehicle (docs/sumo.md, "Meter realisation")."""

    def __init__(self, lib: ModuleType, edge: str = RAMP_UP) -> None:
        self.lib, self.edge = lib, edge
        #: every release: (vehicle id, steps since SUMO started when its front had left)
        self.crossings: list[tuple[str, int]] = []
        self._steps = 0
        self._on: set[str] = set()
        self._braking: set[str] = set()
        self.emergency_stops = self.emergency_braking = 0

    def read(self) -> int:
        """Vehicles released since the last read; updates the safety counts."""
        ids = self.lib.edge.getLastStepVehicleIDs(self.edge)   # upstream first
        now = set(ids)
        self._steps += 1
        gone = self._on - now
        self.crossings += [(v, self._steps) for v in sorted(gone)]
        released = len(gone)
        self._on = now
        veh = self.lib.vehicle
        for v in self.lib.simulation.getEmergencyStoppingVehiclesIDList():
            self.emergency_stops += v in now
        braking = {v for v in ids[-HEAD_VEHICLES:]
                   if veh.getAcceleration(v) < -veh.getDecel(v) - BRAKING_MARGIN}
        self.emergency_braking += len(braking - self._braking)
        self._braking = braking
        return released

    def start_window(self) -> dict[str, int]:
        """The safety counts of the window that closes now; count anew."""
        closed = self.summary()
        self.emergency_stops = self.emergency_braking = 0
        return closed

    def summary(self) -> dict[str, int]:
        """Emergency stops and emergency braking episodes at the meter in the window."""
        return {"emergency_stops": self.emergency_stops,
                "emergency_braking": self.emergency_braking}


@dataclass(frozen=True)
class PeriodMeasurement:
    """What the sensor read over one control period ending at ``cells.t`` (SI).

    ``cells`` are the Edie aggregates of the mainline; ``occupancy_out`` and
    ``flow_out_loop`` the occupancy (fraction) and the flow (veh/s) of the loop on ``down``
    over the period; ``ramp_queue`` the ramp queue at its last step, veh; ``loops`` the
    stations' record and ``probes`` the AV probes at its last step (None without them).
    """

    cells: CellData
    occupancy_out: float
    ramp_queue: int
    loops: LoopObservation | None = None
    probes: ProbeObservation | None = None
    flow_out_loop: float = float("nan")

    @property
    def t(self) -> float:
        """End of the period, s of simulation time."""
        return self.cells.t


class SpeedMoments:
    """Count, sum and sum of squares of per-vehicle speeds (m/s) per class (HV, AV),
    accumulated over vehicle-steps (their sd pools lateral files, the speed profile and
    waves alike: docs/whole_demand.md)."""

    CLASSES = ("h", "a")

    def __init__(self) -> None:
        self.n, self.s1, self.s2 = np.zeros(2), np.zeros(2), np.zeros(2)

    def add(self, speed: np.ndarray, av: np.ndarray) -> None:
        """One step's speeds (m/s) and AV mask."""
        k = av.astype(np.intp)
        self.n += np.bincount(k, minlength=2)
        self.s1 += np.bincount(k, weights=speed, minlength=2)
        self.s2 += np.bincount(k, weights=speed * speed, minlength=2)

    def summary(self) -> dict[str, dict[str, float]]:
        """``speed_mean_kmh``, ``speed_spread_kmh`` (sample sd across vehicle-steps, km/h;
        NaN with fewer than two samples; also as ``speed_sd_kmh``, for reports that read
        that name) and ``speed_samples`` (vehicle-steps), per class."""
        out: dict[str, dict[str, float]] = {"speed_mean_kmh": {}, "speed_spread_kmh": {},
                                            "speed_sd_kmh": {}, "speed_samples": {}}
        for c, n, s1, s2 in zip(self.CLASSES, self.n, self.s1, self.s2, strict=True):
            mean = s1 / n if n else math.nan
            var = max(s2 - s1 * s1 / n, 0.0) / (n - 1) if n > 1 else math.nan
            out["speed_mean_kmh"][c] = float(ms_to_kmh(mean))
            out["speed_spread_kmh"][c] = float(ms_to_kmh(math.sqrt(var)))
            out["speed_sd_kmh"][c] = out["speed_spread_kmh"][c]
            out["speed_samples"][c] = int(n)
        return out


class SumoSensor:
    """Reads an open libsumo run every step; yields one measurement per control period.

    ``length``: L of the measured section, m; ``window``: keep the warm-up ledger and the
    speed moments for a control window (:meth:`start_window`); ``layout``: loop stations
    and AV probes read besides the cells; ``loop_noise``, ``probe_noise``: attached to
    their records (the estimators' assumed errors); ``measure``: read the mainline and the
    loops (False: the meter's reading only).
    """

    def __init__(self, lib: ModuleType, length: float, cfg: SumoConfig,
                 window: bool = False, layout: SensorLayout | None = None,
                 loop_noise: LoopNoise | None = None,
                 probe_noise: ProbeNoise | None = None, measure: bool = True) -> None:
        self.lib, self.measure = lib, measure
        road = cfg.layout
        self.classes = VehicleClasses(lib, road)
        self.stop_line = StopLine(lib) if road is None else StopLine(lib, road.ramp_edge)
        self._end: tuple[float, object, EmissionsLedger] | None = None
        self.mainline = MainlineSensor(lib, length, cfg.cell_length, cfg.step_length,
                                       cfg.steps_per_period, road, self.classes)
        layout = layout or SensorLayout()
        self.loops = LoopSensor(lib, layout.loop_x(length), length, cfg.step_length,
                                cfg.steps_per_period, loop_noise, layout.loop_speed,
                                road) if layout.loops else None
        self.probes = AvProbes(layout.av_probe_share, layout.av_probe_seed, probe_noise) \
            if layout.av_probes else None
        self.queue = 0
        self.downstream = DownstreamLoop(lib, cfg.step_length, cfg.steps_per_period,
                                         downstream_ids(road))
        self.ledger = EmissionsLedger(lib, cfg.step_length) if window else None
        self.window_open = False
        self.speeds = SpeedMoments()
        self.lateral = LateralSampler(lib)

    def start_window(self, t: float) -> WindowStart:
        """Open the control window at ``t`` (s): the system's state now (for the window's
        network measures); from now on speeds are accumulated, fuel no longer."""
        if self.ledger is None or self.window_open:
            raise RuntimeError("start_window needs a sensor made with window=True, once")
        self.window_open = True
        return self.ledger.close(t)

    def end_window(self, t: float) -> None:
        """Close the control window at ``t`` (s): keep the values of the vehicles on the
        network now; from now on only the meter's reading and fuel and CO2 are read."""
        on_network, ledger = window_end(self.lib, t)
        self._end = (t, on_network, ledger)

    def window_end_values(self) -> WindowEnd:
        """The window's end (:meth:`end_window`) with the fuel and CO2 summed since."""
        if self._end is None:
            raise RuntimeError("window_end_values needs end_window first")
        t, on_network, ledger = self._end
        return finish_window(t, on_network, ledger)

    def observe(self, t: float, pending: Sequence[str] | None = None
                ) -> tuple[MeterReading, PeriodMeasurement | None]:
        """Sample the step that ended at ``t`` (s; ``pending``: the vehicles SUMO holds
        back now, :attr:`arzsumo.sumo.simulation.SumoSimulation.pending`): the meter's
        reading, and the period's measurement when the period is complete (else None).
        :attr:`queue` is the ramp queue now."""
        self.queue = ramp_queue(self.lib, pending) if self.classes.layout is None else \
            ramp_queue(self.lib, pending, self.classes.layout.ramp_edge, self.classes.ramp)
        reading = MeterReading(self.queue, self.stop_line.read())
        if self._end is not None:
            self._end[2].add()
            return reading, None
        if not self.measure:
            return reading, None
        down = self.downstream.observe(t)
        cells = self.mainline.collect(t)
        loops = self.loops.observe(t) if self.loops is not None else None
        if self.window_open:
            self.speeds.add(self.mainline.last_speed, self.mainline.last_av)
        elif self.ledger is not None:
            self.ledger.add()
        if cells is None:
            return reading, None
        occupancy, flow = down if down is not None else (float("nan"), float("nan"))
        m = self.mainline
        if self.window_open:     # once per period: a libsumo call per vehicle
            self.lateral.sample(t, m.last_ids, m.last_pos, m.last_speed, m.last_av)
        probes = self.probes.observe(t, m.last_ids, m.last_pos, m.last_speed, m.last_av) \
            if self.probes is not None else None
        return reading, PeriodMeasurement(cells, occupancy, self.queue, loops, probes, flow)
