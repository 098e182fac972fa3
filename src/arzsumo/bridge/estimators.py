"""Estimators of the closed loop on sparse sensors: ASM smoothing and the EnKF.

``[estimation] method`` picks what the controller acts on: ``"none"``, the full probe's
cells (:class:`~arzsumo.bridge.estimator.FundamentalDiagramFill`); ``"smoothing"``
(:class:`SmoothingEstimator`); ``"enkf"`` (:class:`EnkfEstimator`). Both read only the
loops and AV probes; where they have no datum, a density is the design equilibrium's and
a speed Ve. ``observer-etc`` with a method is the ETC on the estimate from the two
boundary stations only (:func:`boundary_only`). :class:`RecordedEstimator` keeps what
the controller got, for ``summary.json["estimation"]``. docs/sumo.md, 'Estimation in the
closed loop'.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arzsumo.bridge.estimator import Estimator, FundamentalDiagramFill, fill_speeds
from arzsumo.control.base import MacroState
from arzsumo.estimate.enkf import BoundaryInput, EnsembleKalmanFilter
from arzsumo.estimate.observations import LoopObservation, ProbeObservation
from arzsumo.estimate.smoothing import CausalSmoother
from arzsumo.estimate.synthetic import interpolate_loops
from arzsumo.evaluation.fields import field_rmse
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import VARIABLES
from arzsumo.scenario.estimation import EstimationSettings
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.sensor import PeriodMeasurement


def filled(eq: Equilibrium, z: np.ndarray) -> np.ndarray:
    """Fields (4, n) with NaN densities at the equilibrium's (veh/m) and NaN speeds at Ve
    of the cell's densities (m/s)."""
    z = np.array(z, float)
    z[0] = np.where(np.isfinite(z[0]), z[0], eq.rho_h)
    z[2] = np.where(np.isfinite(z[2]), z[2], eq.rho_a)
    z[1], z[3] = fill_speeds(eq.params, z[0], z[1], z[2], z[3])
    return z


def boundary_only(obs: LoopObservation) -> LoopObservation:
    """The record of the first and last stations of ``obs`` (x = 0+ and x = L-)."""
    k = [0, obs.x.size - 1]
    tm, hm = (None if a is None else a[:, k] for a in (obs.time_mean, obs.harmonic))
    return LoopObservation(obs.t, obs.period, obs.x[k], obs.flow[:, k], obs.speed[:, k],
                           obs.density[:, k], obs.noise, tm, hm)


def _state(t: float, x: np.ndarray, z: np.ndarray, m: PeriodMeasurement) -> MacroState:
    return MacroState(t, x, z[0], z[1], z[2], z[3], m.occupancy_out)


def sparse_data(m: PeriodMeasurement, boundary: bool
                ) -> tuple[list[LoopObservation], list[ProbeObservation]]:
    """The sparse records of ``m`` an estimator uses (all, or the boundary loops only)."""
    loops = [] if m.loops is None else [boundary_only(m.loops) if boundary else m.loops]
    probes = [] if m.probes is None or boundary else [m.probes]
    return loops, probes


class SmoothingEstimator:
    """Causal ASM of the loop and probe records on the cells ``x`` (m); see the module."""

    def __init__(self, eq: Equilibrium, x: np.ndarray, settings: EstimationSettings,
                 boundary: bool = False) -> None:
        self.eq, self.x = eq, np.asarray(x, float)
        self.smoother = CausalSmoother(self.x, settings.asm)
        self.boundary = boundary
        self.sd: np.ndarray | None = None

    def estimate(self, measurement: PeriodMeasurement, t: float) -> MacroState:
        self.smoother.add(*sparse_data(measurement, self.boundary))
        z = filled(self.eq, self.smoother.estimate(measurement.t))
        return _state(t, self.x, z, measurement)


class EnkfEstimator:
    """EnKF on the cells ``x`` (m), started at the first measurement from the interpolation
    between its loop stations (:func:`filled`); :attr:`sd` the ensemble spread (4, n) of
    the last estimate."""

    def __init__(self, eq: Equilibrium, x: np.ndarray, settings: EstimationSettings,
                 boundary: bool = False) -> None:
        self.eq, self.x = eq, np.asarray(x, float)
        self.options = settings.enkf(self.x.size)
        self.boundary = boundary
        self.filter: EnsembleKalmanFilter | None = None
        self.sd: np.ndarray | None = None

    def estimate(self, measurement: PeriodMeasurement, t: float) -> MacroState:
        m = measurement
        if m.loops is None:
            raise RuntimeError("the EnKF needs loop records (open SUMO with the loops)")
        loops, probes = sparse_data(m, self.boundary)
        p = self.eq.params
        if self.filter is None:
            first = filled(self.eq, interpolate_loops(loops[0], self.x))
            self.filter = EnsembleKalmanFilter(p, first, self.options, t0=m.t)
            if not np.allclose(self.filter.x, self.x):
                raise RuntimeError("the EnKF grid differs from the controller's cells")
            self.filter.analyse(loops, probes)
            est = self.filter.estimate()
        else:
            est = self.filter.step(m.t, BoundaryInput.from_loops(p, m.loops), loops, probes)
        self.sd = est.sd
        return _state(t, self.x, est.mean, m)


@dataclass
class RecordedEstimator:
    """An estimator and what it gave in the control window (t >= 0), per period.

    ``fields`` (4, n) per check, as the controller got them; ``sd`` the EnKF's spread
    (None otherwise); ``interpolation`` the linear interpolation between the period's
    loop stations, speeds filled with Ve (when there are loops); ``measurements``, when
    not None, every measurement handed over (warm-up included: the record an offline pass
    replays, :mod:`arzsumo_studies.estimation.sensor_record`).
    """

    inner: Estimator
    method: str
    sensors: tuple[str, ...]
    eq: Equilibrium
    fields: list[np.ndarray] = field(default_factory=list)
    sd: list[np.ndarray] = field(default_factory=list)
    interpolation: list[np.ndarray] = field(default_factory=list)
    measurements: list[PeriodMeasurement] | None = None

    def estimate(self, measurement: PeriodMeasurement, t: float) -> MacroState:
        if self.measurements is not None:
            self.measurements.append(measurement)
        s = self.inner.estimate(measurement, t)
        if t >= 0.0:
            self.fields.append(np.vstack([s.rho_h, s.v_h, s.rho_a, s.v_a]))
            sd = getattr(self.inner, "sd", None)
            if sd is not None:
                self.sd.append(np.asarray(sd))
            if measurement.loops is not None:
                self.interpolation.append(filled(self.eq, interpolate_loops(
                    measurement.loops, s.x)))
        return s

    def prime(self, warm: list[PeriodMeasurement], t0: float) -> list[np.ndarray]:
        """Feed the warm-up's measurements (times before ``t0``, s) to the method; return
        its estimate (4, n) of each (for the warm-up reference, :mod:`.reference`)."""
        if self.measurements is not None:
            self.measurements.extend(warm)
        states = (self.inner.estimate(m, m.t - t0) for m in warm)
        return [np.vstack([s.rho_h, s.v_h, s.rho_a, s.v_a]) for s in states]


def acting_controller(method: str, controller: str) -> str:
    """The controller that acts in a run of ``controller`` with ``[estimation] method``:
    ``observer-etc`` with a method other than ``none`` becomes ``etc`` on the boundary
    stations' estimate; any other is itself."""
    return "etc" if controller == "observer-etc" and method != "none" else controller


def estimation_stage(settings: EstimationSettings, layout: SensorLayout, controller: str,
                     eq: Equilibrium, x: np.ndarray, keep: bool = False
                     ) -> tuple[RecordedEstimator, str]:
    """The estimator of a run of ``controller`` and the controller that acts on it
    (:func:`acting_controller`); ``keep``: the estimator keeps every measurement
    (:attr:`RecordedEstimator.measurements`)."""
    acting = acting_controller(settings.method, controller)
    boundary = acting != controller        # observer-etc on the boundary stations
    inner: Estimator
    if settings.method == "smoothing":
        inner = SmoothingEstimator(eq, x, settings, boundary)
    elif settings.method == "enkf":
        inner = EnkfEstimator(eq, x, settings, boundary)
    else:
        inner = FundamentalDiagramFill(eq.params)
    sensors = ("loops (boundaries)",) if boundary else layout.kinds
    if layout.loop_speed == "harmonic":
        named = {"loops": "loops (harmonic speed)",
                 "loops (boundaries)": "loops (boundaries, harmonic speed)"}
        sensors = tuple(named.get(k, k) for k in sensors)
    return (RecordedEstimator(inner, settings.method, sensors, eq,
                              measurements=[] if keep else None), acting)


def rmse_by_variable(truth: np.ndarray, est: np.ndarray, ref: tuple[float, ...],
                     periods: int = 1, cells: int = 1) -> dict[str, Any]:
    """RMSE of ``est`` against ``truth`` per variable on blocks of ``periods`` x ``cells``:
    absolute (SI), relative to ``ref`` (the equilibrium's values) and the pairs used."""
    value, n = field_rmse(truth, est, periods, cells)
    return {name: {"absolute": float(value[k]), "relative": float(value[k] / ref[k]),
                   "samples": int(n[k])} for k, name in enumerate(VARIABLES)}


def estimation_scores(truth: np.ndarray, est: RecordedEstimator,
                      eq: Equilibrium) -> dict[str, Any]:
    """``summary.json["estimation"]`` of an estimator's record against ``truth``
    (periods, 4, n): RMSE per variable (absolute SI, relative to the equilibrium,
    samples), the EnKF's mean spread, the RMSE of interpolation between the loops."""
    ref = (eq.rho_h, eq.v_h, eq.rho_a, eq.v_a)
    spread = None
    if len(est.sd) > 1:
        sd = np.asarray(est.sd[1:]).mean(axis=(0, 2))
        spread = {name: {"absolute": float(sd[k]), "relative": float(sd[k] / ref[k])}
                  for k, name in enumerate(VARIABLES)}
    interp = (rmse_by_variable(truth, np.asarray(est.interpolation[1:]), ref)
              if len(est.interpolation) > 1 else None)
    return {"method": est.method, "sensors": list(est.sensors),
            **rmse_by_variable(truth, np.asarray(est.fields[1:]), ref), "spread": spread,
            "interpolation": interp}
