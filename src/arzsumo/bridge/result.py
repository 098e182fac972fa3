"""The result of one co-simulation run: a typed container that outputs, metrics and plots read."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arzsumo.bridge.estimators import RecordedEstimator
from arzsumo.bridge.reference import ReferenceShift
from arzsumo.control.base import ControlLog
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.scenario import Scenario
from arzsumo.scenario.run import RunSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.lateral import LateralRecord
from arzsumo.sumo.run_files import RunFiles
from arzsumo.sumo.simulation import RunReport
from arzsumo.sumo.window import NetworkMeasures


@dataclass
class CoSimResult:
    """Everything a run produced; arrays are per control period (SI, times from control start).

    ``t[k]`` is the end of period k and ``micro``/``replay``/``reference`` (periods, 4,
    cells) the fields then; ``periods`` holds the :class:`PeriodRecord` columns, whose
    ``t`` is the check that started period k. ``start`` (4, cells) is the micro state at
    t = 0 (the last warm-up period, from which the twins start), as ``micro``:
    (rho_h, v_h, rho_a, v_a), NaN speeds in empty cells.
    """

    scenario: Scenario
    settings: RunSettings
    sumo: SumoConfig
    equilibrium: Equilibrium
    q_nominal: float
    t: np.ndarray
    x: np.ndarray
    micro: np.ndarray
    replay: np.ndarray
    reference: np.ndarray
    periods: dict[str, np.ndarray]
    controller_log: ControlLog
    reference_log: ControlLog
    meter: dict[str, Any]
    report: RunReport | None
    twin_status: dict[str, Any]
    placement: str
    wall_time: float
    timings: dict[str, float]
    #: meter counts from t = 0 to the start of control, and that time (``duration_s``, s)
    warmup_meter: dict[str, float] = field(default_factory=dict)
    #: SUMO's network measures (control window, whole run) and its tripinfo file
    network: NetworkMeasures | None = None
    #: per-vehicle speed moments on the section over the control window, per class
    #: (``speed_mean_kmh``, ``speed_spread_kmh`` and its former name ``speed_sd_kmh``,
    #: ``speed_samples``)
    section_speed: dict[str, dict[str, float]] = field(default_factory=dict)
    start: np.ndarray | None = None
    #: what the controller acted on, aligned with ``micro`` (periods, 4, cells), and the
    #: estimator's record (:class:`~arzsumo.bridge.estimators.RecordedEstimator`)
    estimate: np.ndarray | None = None
    estimator: RecordedEstimator | None = None
    #: the offset subtracted from the controller's input (:mod:`~arzsumo.bridge.reference`),
    #: None when its deviations are measured from the equilibrium
    shift: ReferenceShift | None = None
    #: one snapshot per control period of the window (the last step of period k with
    #: ``micro[k]``): positions, speeds, lateral offsets and classes of the vehicles on main
    lateral: LateralRecord | None = None
    #: the SUMO configuration the run ran (``run.sumocfg``, ``sumo/``) and, with
    #: ``[sumo] fcd``, its FCD output, to be placed into the results directory
    files: RunFiles | None = None
    #: what the ``[disturbance]`` did (:class:`arzsumo.sumo.disturbance.DisturbanceSchedule`
    #: ``applied``: SUMO times in s, speeds in m/s); None without one
    disturbance: dict[str, Any] | None = None
    #: the stationary state (4, cells; SI) and band (1) the window's deviation is measured
    #: from: SUMO's cells over the warm-up's last minutes (:mod:`arzsumo.evaluation.decay`)
    stationary: np.ndarray | None = None
    stationary_band: float = float("nan")
    #: the sd (veh/s) of the acting law's output noise on the warm-up's estimate that sized
    #: its trigger's dead band (``[design] noise_from_estimate``); None: not measured
    trigger_noise: float | None = None
