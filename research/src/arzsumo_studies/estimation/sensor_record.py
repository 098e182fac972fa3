"""Estimation offline: one SUMO run's sensor data, replayed through any layout and estimator.

:func:`record_run` makes one open-loop run with a *superset* of sensors (loop stations
every :data:`SUPERSET_SPACING` m, both boundaries, every AV a probe) and keeps every
period's measurement, warm-up included, as a :class:`SensorRecord` (``.npz`` on disk),
both loop speeds included. :func:`replay_estimation` hands a layout's share of it to a
scenario's estimator as the closed loop would, and
:func:`arzsumo.bridge.estimators.estimation_scores` scores it as
``summary.json["estimation"]`` does; the numbers equal those inside a run to 1e-9
(``research/tests/measures/test_sensor_record.py``: loading stations moves no vehicle).
research/readings/estimation_layouts.md.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.bridge.estimators import RecordedEstimator, estimation_stage
from arzsumo.estimate.observations import LoopObservation, ProbeObservation
from arzsumo.io import atomic_file
from arzsumo.scenario import Scenario
from arzsumo.scenario.estimation import EstimationSettings
from arzsumo.sumo.loops import placed_positions
from arzsumo.sumo.measure import CellData
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.sensor import PeriodMeasurement

#: station spacing of the recorded superset, m (every layout's stations are among them)
SUPERSET_SPACING = 50.0
#: the recorded superset, as ``[sensing]`` keys
SUPERSET = {"sensing.kinds": ["loops", "av_probes"],
            "sensing.loop_spacing_m": SUPERSET_SPACING, "sensing.av_probe_share": 1.0}
_CELLS = ("rho_h", "rho_a", "q_h", "q_a", "samples_h", "samples_a")
_FLOWS = ("inflow_h", "inflow_a", "outflow_h", "outflow_a")


@dataclass(frozen=True)
class SensorRecord:
    """Every period's measurement of a run, as arrays (SI; P periods, n cells, J stations).

    ``start`` is the index of the start of control (t = 0; the periods before it are the
    warm-up's). Cells: ``t``, ``window`` (P,), ``x`` (n,), ``rho_h`` ... ``samples_a``
    (P, n), ``flows`` (P, 4) inflow h, a and outflow h, a (veh/s), ``occupancy`` and
    ``queue`` (P,). Loops: ``loop_x`` (J,), ``loop_period`` (P,), ``flow``, ``speed``
    (time-mean), ``density``, ``speed_harmonic`` (P, 2, J; None in records saved before
    it existed). Probes (every AV): ``probe_n`` (P,) per period, ``probe_x``, ``probe_v``
    (sum of probe_n,).
    """

    start: int
    t: np.ndarray
    window: np.ndarray
    x: np.ndarray
    rho_h: np.ndarray
    rho_a: np.ndarray
    q_h: np.ndarray
    q_a: np.ndarray
    samples_h: np.ndarray
    samples_a: np.ndarray
    flows: np.ndarray
    occupancy: np.ndarray
    queue: np.ndarray
    loop_x: np.ndarray
    loop_period: np.ndarray
    flow: np.ndarray
    speed: np.ndarray
    density: np.ndarray
    probe_n: np.ndarray
    probe_x: np.ndarray
    probe_v: np.ndarray
    speed_harmonic: np.ndarray | None = None

    @classmethod
    def from_measurements(cls, ms: list[PeriodMeasurement], start: int) -> SensorRecord:
        """From a run's measurements (each with loops and probes) and the start index."""
        if any(m.loops is None or m.probes is None or m.loops.time_mean is None
               or m.loops.harmonic is None for m in ms):
            raise ValueError("a sensor record needs SUMO's loops (both speeds) and AV "
                             "probes in every period")
        cells = {k: np.array([getattr(m.cells, k) for m in ms], float) for k in _CELLS}
        loops = [m.loops for m in ms if m.loops is not None]
        probes = [m.probes for m in ms if m.probes is not None]
        return cls(start, np.array([m.t for m in ms]), np.array([m.cells.window for m in ms]),
                   np.asarray(ms[0].cells.x, float), **cells,
                   flows=np.array([[getattr(m.cells, k) for k in _FLOWS] for m in ms]),
                   occupancy=np.array([m.occupancy_out for m in ms], float),
                   queue=np.array([m.ramp_queue for m in ms], float),
                   loop_x=np.asarray(loops[0].x, float),
                   loop_period=np.array([o.period for o in loops]),
                   flow=np.array([o.flow for o in loops]),
                   speed=np.array([o.time_mean for o in loops]),
                   speed_harmonic=np.array([o.harmonic for o in loops]),
                   density=np.array([o.density for o in loops]),
                   probe_n=np.array([p.x.size for p in probes], int),
                   probe_x=np.concatenate([p.x for p in probes]),
                   probe_v=np.concatenate([p.v for p in probes]))

    def truth(self) -> np.ndarray:
        """The full probe's fields (rho_h, v_h, rho_a, v_a) of the control periods after
        the start, (P - start - 1, 4, n), NaN speeds in empty cells (``res.micro``)."""
        k = slice(self.start + 1, None)
        with np.errstate(invalid="ignore", divide="ignore"):
            v_h = np.where(self.samples_h[k] > 0, self.q_h[k] / self.rho_h[k], np.nan)
            v_a = np.where(self.samples_a[k] > 0, self.q_a[k] / self.rho_a[k], np.nan)
        return np.stack([self.rho_h[k], v_h, self.rho_a[k], v_a], axis=1)

    def stations(self, layout: SensorLayout, length: float) -> np.ndarray:
        """Indices of the recorded stations a layout has (all of them must be recorded)."""
        if not layout.loops:
            return np.empty(0, int)
        want = placed_positions(layout.loop_x(length), length)
        idx = np.searchsorted(self.loop_x, want - 1e-6)
        ok = idx < self.loop_x.size
        if not ok.all() or not np.allclose(self.loop_x[idx], want, atol=1e-6):
            raise ValueError(f"stations at {want.tolist()} m are not all among the "
                             f"recorded {self.loop_x.tolist()} m")
        return idx

    def measurements(self, layout: SensorLayout, est: EstimationSettings,
                     length: float) -> list[PeriodMeasurement]:
        """The measurements a run with ``layout`` would have had, with the noise models
        of ``est`` attached (AV probes only with ``av_probe_share = 1``, as recorded); the
        loops' ``speed`` is the layout's ``loop_speed``."""
        if layout.av_probes and layout.av_probe_share != 1.0:
            raise ValueError("the record holds every AV: av_probe_share must be 1")
        harmonic = self.speed_harmonic
        if harmonic is None and layout.loops and layout.loop_speed == "harmonic":
            raise ValueError("the record has no harmonic loop speeds (saved before they "
                             "were recorded): record the run again")
        speed = harmonic if layout.loop_speed == "harmonic" and harmonic is not None \
            else self.speed
        idx = self.stations(layout, length)
        ends = np.cumsum(self.probe_n)
        out = []
        for k, t in enumerate(self.t):
            cells = CellData(float(t), float(self.window[k]), self.x,
                             *(getattr(self, c)[k] for c in _CELLS),
                             *(float(f) for f in self.flows[k]))
            loops = LoopObservation(float(t), float(self.loop_period[k]), self.loop_x[idx],
                                    self.flow[k][:, idx], speed[k][:, idx],
                                    self.density[k][:, idx], est.loop_noise,
                                    self.speed[k][:, idx],
                                    None if harmonic is None else harmonic[k][:, idx]) \
                if layout.loops else None
            p = slice(ends[k] - self.probe_n[k], ends[k])
            probes = ProbeObservation(float(t), "a", self.probe_x[p], self.probe_v[p], 1.0,
                                      est.probe_noise) if layout.av_probes else None
            out.append(PeriodMeasurement(cells, float(self.occupancy[k]),
                                         int(self.queue[k]), loops, probes))
        return out

    def save(self, path: Path, info: dict[str, Any] | None = None) -> None:
        """Write the arrays (and ``info``, JSON) to ``path`` (.npz, atomically)."""
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {f.name: getattr(self, f.name) for f in fields(self)
                  if getattr(self, f.name) is not None}
        with atomic_file(path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, **arrays, info=json.dumps(info or {}))

    @classmethod
    def load(cls, path: Path) -> tuple[SensorRecord, dict[str, Any]]:
        """The record and info of :meth:`save`."""
        with np.load(path) as z:
            arrays = {f.name: z[f.name] for f in fields(cls) if f.name in z.files}
            info = json.loads(str(z["info"]))
        arrays["start"] = int(arrays["start"])
        return cls(**arrays), info


def replay_estimation(record: SensorRecord, scenario: Scenario,
                      controller: str = "open") -> RecordedEstimator:
    """The scenario's estimator fed the record as the closed loop feeds it (module
    docstring); the design equilibrium is the scenario's (``operating_point =
    "scenario"``)."""
    ms = record.measurements(scenario.sensing, scenario.estimation, scenario.params.length)
    start = ms[record.start]
    est, _ = estimation_stage(scenario.estimation, scenario.sensing, controller,
                              scenario.equilibrium, start.cells.x)
    est.prime(ms[:record.start], start.t)
    est.estimate(start, 0.0)
    for m in ms[record.start + 1:]:
        est.estimate(m, m.t - start.t)
    return est


def record_run(scenario: Scenario, seed: int, warmup: float, horizon: float
               ) -> tuple[SensorRecord, dict[str, Any]]:
    """One open-loop run of ``scenario`` with the superset of sensors (:data:`SUPERSET`):
    its record and a few numbers (``wall_time_s``, ``periods``)."""
    import time

    from arzsumo.bridge.cosim import run_cosimulation
    from arzsumo.bridge.session import prepare_run

    t0 = time.perf_counter()
    sc = scenario.with_({**SUPERSET, "estimation.method": "none"})
    run = prepare_run(sc, controller="open", seed=seed, horizon=horizon, warmup=warmup)
    res = run_cosimulation(run, keep_measurements=True)
    ms = res.estimator.measurements if res.estimator is not None else None
    if not ms:
        raise RuntimeError("the run kept no measurements")
    start = len(ms) - res.t.size - 1
    record = SensorRecord.from_measurements(ms, start)
    if not np.array_equal(record.truth(), res.micro, equal_nan=True):
        raise RuntimeError("the record's cells differ from the run's fields")
    return record, {"wall_time_s": time.perf_counter() - t0, "periods": int(res.t.size)}
