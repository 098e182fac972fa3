"""Calibration: what SUMO actually does, in the model's terms (docs/sumo.md, "Calibration").

Runs the scenario's network over demand levels (:data:`DEMANDS`, or :data:`SCALES` of a
user's route files' demand) and meter green shares in worker processes (libsumo holds one
simulation per process) and fits Ve_i(AO) = V_i (1 - (AO / AO_max_i)^gamma_i) per class
to Edie cell data; measures the meter curve and the equilibrium SUMO holds. Each run is
:func:`run_fixed_meter`: the open loop at a fixed plan, measured every step (tests use it
too; the closed loop with the PDE controllers lives in the bridge).
"""

from __future__ import annotations

import logging
import multiprocessing
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import curve_fit

from arzsumo.errors import ArzsumoError
from arzsumo.interrupts import worker_pool
from arzsumo.model.characteristic import linearize
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import power_law_speed
from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import InitialVehicle
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.measure import MeasurementLog
from arzsumo.sumo.network import RAMP_UP
from arzsumo.sumo.paths import SumoError
from arzsumo.sumo.period_reads import OpenLoopPeriod
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import RunReport, open_simulation
from arzsumo.units import veh_h_to_veh_s

log = logging.getLogger(__name__)

#: Class demands (veh/h) of the paper's Table diffdemands, plus a light level for free flow.
DEMANDS: dict[str, tuple[float, float]] = {
    "light": (1700.0, 700.0), "low": (3461.0, 1505.0), "medium": (4104.0, 1560.0),
    "high": (4555.0, 1955.0),
}

#: Demand levels on a user's network whose route files carry the demand: SUMO's --scale
#: of that demand ("medium" is the demand as written, the meter curve's level).
SCALES: dict[str, float] = {"light": 0.4, "low": 0.8, "medium": 1.0, "high": 1.15}


@dataclass(frozen=True)
class CalibrationPlan:
    """Which runs to make: horizon and warm-up (s), window (s), green shares, demands."""

    horizon: float = 450.0
    warmup: float = 150.0
    window: float = 10.0
    curve_shares: tuple[float, ...] = (0.0, 0.25, 0.5, 0.75, 1.0)
    fd_levels: tuple[str, ...] = ("light", "low", "high")
    fd_shares: tuple[float, ...] = (0.0, 1.0)
    min_samples: float = 20.0

    def runs(self, base: SumoConfig) -> list[tuple[str, float, SumoConfig]]:
        """(demand level, green share, config) of every run: the level as class demands
        or, where the user's route files carry the demand, as its scale."""
        out = []
        level_shares = [("medium", g) for g in self.curve_shares]
        level_shares += [(lv, g) for lv in self.fd_levels for g in self.fd_shares]
        scaled = base.layout is not None and bool(base.layout.route_files)
        for level, g in level_shares:
            qh, qa = DEMANDS[level]
            demand = ({"demand_scale": SCALES[level]} if scaled else
                      {"demand_h": float(veh_h_to_veh_s(qh)),
                       "demand_a": float(veh_h_to_veh_s(qa))})
            out.append((level, g, base.with_(**demand, horizon=self.horizon,
                                             control_period=self.window, green_share=g)))
        return out


@dataclass(frozen=True)
class RunResult:
    """Measurements (per control period), vehicle accounting and meter counts of a run."""

    cfg: SumoConfig
    green_share: float
    measurements: MeasurementLog
    report: RunReport
    meter: dict[str, Any]
    ramp_passed: int


def run_fixed_meter(params: ModelParameters, cfg: SumoConfig, green_share: float | None = None,
                    *, initial: Sequence[InitialVehicle] = (), net_dir: Path | None = None,
                    measure: bool = True, curve: GreenShareCurve = DEFAULT_CURVE) -> RunResult:
    """Run ``cfg.horizon`` seconds with the meter at ``green_share`` (default: nominal).

    ``green_share`` in [0, 1] (0: always red, 1: always green); ``cfg.control_period`` is
    the measurement window; ``initial``: vehicles placed at t = 0; ``measure``: collect
    Edie aggregates every step (False: only the meter acts).
    """
    g = cfg.green_share if green_share is None else green_share
    cfg = cfg.with_(green_share=g)
    measurements = MeasurementLog()

    def keep(p: OpenLoopPeriod) -> None:
        if p.measurement is not None:
            measurements.append(p.measurement.cells)

    with open_simulation(params, cfg, initial=initial, net_dir=net_dir) as sim:
        plant = SumoPlant(sim, params.length, cfg, curve, measure=measure)
        plant.run_open_loop(on_period=keep, until=cfg.horizon)
        # ramp vehicles past the meter: inserted minus those still upstream of it
        ramp = cfg.layout.ramp_edge if cfg.layout is not None else RAMP_UP
        ramp_passed = sim.inserted_ramp - int(sim.lib.edge.getLastStepVehicleNumber(ramp))
    if sim.report is None:  # pragma: no cover - close() failed to read SUMO's counts
        raise SumoError("SUMO closed without a final report")
    log.info("%s", sim.report.summary())
    return RunResult(cfg, g, measurements, sim.report, plant.meter_summary(), ramp_passed)


@dataclass(frozen=True)
class RunData:
    """Per-window Edie data of one calibration run (after warm-up), SI."""

    level: str
    green_share: float
    rho_h: np.ndarray
    rho_a: np.ndarray
    v_h: np.ndarray
    v_a: np.ndarray
    samples_h: np.ndarray
    samples_a: np.ndarray
    outflow: float
    inflow: float
    delivered: float
    collisions: int | None      # None: the collision check was off
    meter: dict[str, float]


def _run_one(params: ModelParameters, cfg: SumoConfig, level: str, g: float,
             warmup: float) -> RunData:
    res = run_fixed_meter(params, cfg, g)
    m = res.measurements
    keep = m.array("t") > warmup
    out = m.array("outflow_h")[keep] + m.array("outflow_a")[keep]
    inflow = m.array("inflow_h")[keep] + m.array("inflow_a")[keep]
    return RunData(level, g, m.array("rho_h")[keep], m.array("rho_a")[keep],
                   m.array("v_h")[keep], m.array("v_a")[keep], m.array("samples_h")[keep],
                   m.array("samples_a")[keep], float(out.mean()), float(inflow.mean()),
                   res.report.delivered_main, res.report.collisions, res.meter)


def run_calibration_runs(params: ModelParameters, base: SumoConfig, plan: CalibrationPlan,
                         jobs: int = 2) -> list[RunData]:
    """Make the runs of ``plan``, ``jobs`` SUMO processes at a time."""
    runs = plan.runs(base)
    ctx = multiprocessing.get_context("spawn")
    with worker_pool(max(1, jobs), ctx) as pool:
        futures = [pool.submit(_run_one, params, cfg, lv, g, plan.warmup)
                   for lv, g, cfg in runs]
        results = []
        for (lv, g, _), fut in zip(runs, futures, strict=True):
            data = fut.result()
            log.info("run %-6s g = %.2f: outflow %.0f veh/h, mainline delivered %.1f %%", lv, g,
                     data.outflow * 3600, 100 * data.delivered)
            results.append(data)
    return results


# -- fundamental diagram fit: V (1 - (AO / AO_max)^gamma) per class, m/s ------------------
@dataclass(frozen=True)
class ClassFit:
    """Fitted FD of one class: V (m/s), AO_max, gamma; R^2 and RMSE (m/s); paper's R^2."""

    v_free: float
    ao_max: float
    gamma: float
    r2: float
    rmse: float
    n: int
    r2_paper: float
    rmse_paper: float


def _scores(y: np.ndarray, f: np.ndarray) -> tuple[float, float]:
    ss_res = float(np.sum((y - f) ** 2))
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    return (1.0 - ss_res / ss_tot if ss_tot > 0 else float("nan"),
            float(np.sqrt(ss_res / y.size)))


def fit_class(ao: np.ndarray, v: np.ndarray, paper: tuple[float, float, float]) -> ClassFit:
    """Least-squares fit of one class's FD to (AO, speed m/s) points.

    The free-flow speed is bounded by 1.02 times the paper's V_i, which is the vehicle
    type's maximum speed in SUMO: no SUMO speed can exceed it.
    """
    if ao.size < 5:
        raise ArzsumoError(f"calibration points = {ao.size} are too few; allowed: at least 5 "
                           "(longer runs or more demand levels)")
    v_cap = 1.02 * paper[0]
    p0 = (min(max(float(v.max()), 1.0), v_cap), min(0.99, max(0.3, float(ao.max()) * 1.05)),
          1.5)
    popt, _ = curve_fit(power_law_speed, ao, v, p0=p0,
                        bounds=([0.5, 0.05, 0.1], [v_cap, 1.0, 8.0]), maxfev=20000)
    r2, rmse = _scores(v, power_law_speed(ao, *popt))
    r2p, rmsep = _scores(v, np.maximum(power_law_speed(ao, *paper), 0.0))
    return ClassFit(*(float(p) for p in popt), r2, rmse, int(ao.size), r2p, rmsep)


def fd_points(params: ModelParameters, runs: list[RunData],
              min_samples: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(AO, speed) points per class from cells with at least ``min_samples`` vehicle-steps."""
    rho_h = np.concatenate([r.rho_h.ravel() for r in runs])
    rho_a = np.concatenate([r.rho_a.ravel() for r in runs])
    ao = (params.area_h * rho_h + params.area_a * rho_a) / params.road_width
    out = {}
    for cls in ("h", "a"):
        v = np.concatenate([getattr(r, f"v_{cls}").ravel() for r in runs])
        s = np.concatenate([getattr(r, f"samples_{cls}").ravel() for r in runs])
        ok = (s >= min_samples) & np.isfinite(v)
        out[cls] = (ao[ok], v[ok])
    return out


@dataclass
class Calibration:
    """Everything ``arzsumo calibrate`` reports (SI)."""

    params: ModelParameters
    calibrated: ModelParameters
    fits: dict[str, ClassFit]
    curve: GreenShareCurve
    points: dict[str, tuple[np.ndarray, np.ndarray]]
    equilibrium: dict[str, Any] = field(default_factory=dict)
    runs: list[dict[str, Any]] = field(default_factory=list)


def measured_equilibrium(runs: list[RunData], calibrated: ModelParameters,
                         nominal: float, x_from: int = 4) -> dict[str, Any]:
    """Mean state of the medium-demand run at the nominal green share and its regime.

    Averages cells from index ``x_from`` on (upstream cells feel the insertion point) over
    the windows after warm-up; lambda_4 comes from the calibrated model at those densities.
    """
    run = min((r for r in runs if r.level == "medium"),
              key=lambda r: abs(r.green_share - nominal))
    rho_h, rho_a = run.rho_h[:, x_from:], run.rho_a[:, x_from:]
    q_h = np.nansum(run.v_h[:, x_from:] * rho_h) / rho_h.size
    q_a = np.nansum(run.v_a[:, x_from:] * rho_a) / rho_a.size
    mh, ma = float(rho_h.mean()), float(rho_a.mean())
    eq: dict[str, Any] = {"green_share": run.green_share, "rho_h": mh, "rho_a": ma,
                          "v_h": q_h / mh if mh else float("nan"),
                          "v_a": q_a / ma if ma else float("nan"),
                          "outflow": run.outflow, "inflow": run.inflow,
                          "delivered": run.delivered}
    eq["ao"] = (calibrated.area_h * mh + calibrated.area_a * ma) / calibrated.road_width
    try:
        model_eq = Equilibrium(calibrated, mh, ma)
        lin = linearize(model_eq)
        eq.update(model_v_h=model_eq.v_h, model_v_a=model_eq.v_a,
                  eigenvalues=[float(v) for v in lin.eigenvalues], regime=lin.regime)
    except ArzsumoError as exc:
        eq.update(regime="undefined", note=str(exc))
    return eq


def calibrate(params: ModelParameters, base: SumoConfig, plan: CalibrationPlan | None = None,
              jobs: int = 2) -> Calibration:
    """Run the calibration of ``plan`` and fit it; see the module docstring."""
    plan = plan or CalibrationPlan()
    runs = run_calibration_runs(params, base, plan, jobs)
    points = fd_points(params, runs, plan.min_samples)
    paper = {"h": (params.v_free_h, params.ao_max_h, params.gamma_h),
             "a": (params.v_free_a, params.ao_max_a, params.gamma_a)}
    fits = {c: fit_class(*points[c], paper[c]) for c in ("h", "a")}
    calibrated = params.with_(v_free_h=fits["h"].v_free, ao_max_h=fits["h"].ao_max,
                              gamma_h=fits["h"].gamma, v_free_a=fits["a"].v_free,
                              ao_max_a=fits["a"].ao_max, gamma_a=fits["a"].gamma)
    medium = sorted((r for r in runs if r.level == "medium"), key=lambda r: r.green_share)
    curve = GreenShareCurve(tuple(r.green_share for r in medium),
                            tuple(r.outflow for r in medium))
    return Calibration(params, calibrated, fits, curve, points,
                       measured_equilibrium(runs, calibrated, base.green_share),
                       [{"level": r.level, "green_share": r.green_share, "outflow": r.outflow,
                         "inflow": r.inflow, "delivered": r.delivered,
                         "collisions": r.collisions,
                         **{f"meter_{k}": v for k, v in r.meter.items()}} for r in runs])
