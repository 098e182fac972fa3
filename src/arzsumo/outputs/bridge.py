"""Results of a co-simulation: tables, ``summary.json`` and plots, written atomically.

Every file of ``DIR``, column (with units, in the Parquet field metadata from
:mod:`arzsumo.schema`) and summary key, and the counting windows of the meter's counts
(the control window; the warm-up's apart under ``warmup``), are described in
docs/outputs.md, "``arzsumo run``".
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from arzsumo.bridge.compare import row_of
from arzsumo.bridge.delay import compensated_delay
from arzsumo.bridge.estimator import fill_speeds
from arzsumo.bridge.estimators import estimation_scores, rmse_by_variable
from arzsumo.bridge.result import CoSimResult
from arzsumo.control.base import ControlLog
from arzsumo.control.events import release_time
from arzsumo.evaluation.authority import authority
from arzsumo.evaluation.decay import decay, deviation_norm
from arzsumo.evaluation.fields import oscillation, wave_travel
from arzsumo.evaluation.stationarity import count_trend
from arzsumo.io import json_safe
from arzsumo.model.characteristic import linearize
from arzsumo.model.params import VARIABLES
from arzsumo.outdir import OutputDir, atomic_dir, target_of
from arzsumo.outputs.run_summary import (
    Accounting,
    RunIdentity,
    RunSummary,
    WindowCounts,
)
from arzsumo.outputs.waves import waves_summary
from arzsumo.pde.metrics import performance
from arzsumo.schema import CELLS, PERIODS, with_units
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km
from arzsumo.version import __version__

#: SUMO's tripinfo output of the run (every loaded vehicle), gzip-compressed
TRIPINFO_GZ = "tripinfo.xml.gz"
#: the run's row of ``arzsumo compare``'s table, every column (``arzsumo run`` prints
#: the key ones)
SUMMARY_CSV = "summary.csv"


#: summary index -> its attribute of :class:`arzsumo.pde.metrics.ClassIndices`
_INDEX_ATTRS = {"TTT": "J_TTT", "total_delay": "total_delay", "J_fuel": "J_fuel",
                "J_discom": "J_discom"}


def _indices(res: CoSimResult, fields: np.ndarray) -> dict[str, Any]:
    """TTT, total delay, J_fuel, J_discom of fields (periods, 4, cells) up to their first NaN."""
    p = res.scenario.params
    ok = np.all(np.isfinite(fields[:, [0, 2]]), axis=(1, 2))
    n = int(np.argmin(ok)) if not ok.all() else ok.size
    if n < 2:
        return {**dict.fromkeys(_INDEX_ATTRS), "until_s": float(res.t[n - 1]) if n else 0.0}
    f = fields[:n].copy()
    f[:, 1], f[:, 3] = fill_speeds(p, f[:, 0], f[:, 1], f[:, 2], f[:, 3])
    perf = performance(p, res.t[:n], res.x, f)
    out: dict[str, Any] = {key: {c: getattr(getattr(perf, c), attr) for c in ("h", "a", "total")}
                           for key, attr in _INDEX_ATTRS.items()}
    return {**out, "until_s": float(res.t[n - 1])}


#: resolution of ``rmse_blocks``: 100 m x 10 s keeps stop-and-go waves (hundreds of metres,
#: a minute or more) and averages out most counting noise of the 50 m x 1 s cells
RMSE_BLOCK_M, RMSE_BLOCK_S = 100.0, 10.0


def rmse(res: CoSimResult, twin: np.ndarray, periods: int = 1,
         cells: int = 1) -> dict[str, dict[str, float]]:
    """RMSE of a twin against the micro fields per variable: absolute (SI) and relative to
    the equilibrium value, at blocks of ``periods`` x ``cells`` (1 x 1: the control grid);
    pairs where either is NaN (empty cells, re-synchronised periods) are skipped."""
    eq = res.equilibrium
    return rmse_by_variable(res.micro, twin, (eq.rho_h, eq.v_h, eq.rho_a, eq.v_a), periods,
                            cells)


def rmse_blocks(res: CoSimResult) -> dict[str, Any]:
    """Both twins' RMSE on RMSE_BLOCK_M x RMSE_BLOCK_S block means (``summary["rmse_blocks"]``)."""
    periods, cells = _blocks(res)
    return {"block_m": cells * res.sumo.cell_length,
            "block_s": periods * res.sumo.control_period,
            "replay": rmse(res, res.replay, periods, cells),
            "reference": rmse(res, res.reference, periods, cells)}


def section_trend(res: CoSimResult) -> dict[str, Any] | None:
    """Trend of the section's vehicle count over the control window
    (:func:`arzsumo.evaluation.stationarity.count_trend`); None when too short."""
    dx = float(res.x[1] - res.x[0]) if res.x.size > 1 else float(res.sumo.cell_length)
    count = np.nansum(res.micro[:, 0] + res.micro[:, 2], axis=1) * dx
    try:
        return count_trend(count, res.sumo.control_period).as_dict()
    except ValueError:
        return None


def estimation_summary(res: CoSimResult) -> dict[str, Any] | None:
    """How well the state the controller acted on matched the full probe's cells
    (:func:`arzsumo.bridge.estimators.estimation_scores`), and the reference of a PDE
    controller's deviations (docs/outputs.md, ``estimation.*``); None without an estimate."""
    est = res.estimator
    if est is None or res.estimate is None or not res.estimate.size:
        return None
    return {**estimation_scores(res.micro, est, res.equilibrium),
            "reference": res.scenario.estimation.reference,
            "reference_offset": res.shift.means() if res.shift else None}


def actuation_summary(res: CoSimResult) -> dict[str, Any]:
    """``summary.json["actuation"]``: the ``[actuation]`` limits used (SI; null: off), how
    often they acted, the delay compensation, the trigger's noise and dead band
    (:mod:`arzsumo.bridge.trigger_noise`), the actuator and its authority
    (:mod:`arzsumo.evaluation.authority`); docs/outputs.md, ``actuation.*``."""
    act, per = res.scenario.actuation, res.periods
    n = int(per["t"].size)
    sat, rate = int(np.sum(per["saturated"] > 0)), int(np.sum(per["rate_limited"] > 0))
    off = res.settings.controller == "open"
    return {"u_max_fraction": act.u_max_fraction,
            "u_max": act.u_max_fraction * res.q_nominal if act.u_max_fraction else None,
            "u_rate_max": act.u_rate_max or None,
            "rate_step": act.u_rate_max * res.sumo.control_period if act.u_rate_max else None,
            "ramp_bound": act.ramp_bound, "anti_windup": act.anti_windup,
            "applies": not off, "periods": n, "saturated_periods": sat,
            "rate_limited_periods": rate, "saturated_share": sat / n if n else None,
            "rate_limited_share": rate / n if n else None,
            "delay_compensation": compensated_delay(res.scenario, res.settings.controller),
            "meter_gain": act.meter_gain, "hold_plan_in_range": act.hold_plan_in_range,
            "trigger_output_noise": res.trigger_noise,
            "trigger_dead_band": (None if res.trigger_noise is None else
                                  res.scenario.design.noise_k * math.sqrt(2.0)
                                  * res.trigger_noise),
            "actuator": ("speed_limit" if np.isfinite(per["speed_limit"]).any()
                         else "meter"),
            "authority": authority(per["u_applied"], per["outflow_h"] + per["outflow_a"],
                                   res.sumo.control_period, AUTHORITY_WINDOW_S).as_dict()}


#: the window of the authority's means, s: a minute, many meter cycles and less than the
#: stop-and-go's period
AUTHORITY_WINDOW_S = 60.0


def warmup_summary(res: CoSimResult) -> dict[str, Any]:
    """The warm-up's meter counts, labelled as such (``summary.json["warmup"]``)."""
    w = res.warmup_meter
    return {"window": "warm-up: t = 0 of SUMO to the start of control; these counts are "
                      "not in the top-level (control window) counts",
            "duration_s": float(w["duration_s"]), "plan_changes": int(w["plan_changes"]),
            "light_changes": int(w["light_changes"]), "max_ramp_queue": int(w["max_queue"])}


#: ``summary.json["section"]["window"]``
SECTION_WINDOW = ("measured section x in [0, L] over the control window: indices from the "
                  "Edie cells, speed moments from every vehicle on main every step, wave "
                  "measures from block means of the Edie speeds and, per lateral file, "
                  "of one snapshot of the vehicles per control period")


def _blocks(res: CoSimResult) -> tuple[int, int]:
    """Periods and cells of a RMSE_BLOCK_S x RMSE_BLOCK_M block."""
    return (max(1, round(RMSE_BLOCK_S / res.sumo.control_period)),
            max(1, round(RMSE_BLOCK_M / res.sumo.cell_length)))


def speed_oscillation(res: CoSimResult) -> dict[str, Any]:
    """Per class, the micro speed's oscillation (km/h) on RMSE_BLOCK_M x RMSE_BLOCK_S
    blocks (:func:`arzsumo.evaluation.fields.oscillation`): the waves alone."""
    periods, cells = _blocks(res)
    sd = oscillation(res.micro[:, [1, 3]], periods, cells)
    return {"speed_oscillation_kmh": {"h": float(ms_to_kmh(sd[0])),
                                      "a": float(ms_to_kmh(sd[1]))},
            "oscillation_block_m": cells * res.sumo.cell_length,
            "oscillation_block_s": periods * res.sumo.control_period}


#: the cross-correlation of ``speed_wave``: places this far apart (m), lags up to (s);
#: 150 s resolves waves down to 6 km/h (a congested lambda_4 is about -11 km/h)
WAVE_GAP_M, WAVE_MAX_LAG_S = 250.0, 150.0


def speed_wave(res: CoSimResult) -> dict[str, Any]:
    """Per class, which way the micro speed fluctuations travel
    (:func:`arzsumo.evaluation.fields.wave_travel` over places WAVE_GAP_M apart; speed in
    km/h, > 0 downstream, the way the meter cannot reach)."""
    dx = float(res.x[1] - res.x[0]) if res.x.size > 1 else float(res.sumo.cell_length)
    gap = max(1, round(WAVE_GAP_M / dx))
    out: dict[str, Any] = {"gap_m": gap * dx, "max_lag_s": WAVE_MAX_LAG_S}
    for c, k in (("h", 1), ("a", 3)):
        w = wave_travel(res.micro[:, k], res.sumo.control_period, dx, gap, WAVE_MAX_LAG_S)
        out[c] = {"speed_kmh": float(ms_to_kmh(w["speed"])), "lag_s": w["lag_s"],
                  "peak_corr": w["peak_corr"], "pairs": w["pairs"]}
    return out


def section_summary(res: CoSimResult, micro: dict[str, Any]) -> dict[str, Any]:
    """``summary.json["section"]``: the per-vehicle speed moments, the measures of the
    functions below and the micro indices ``micro`` (:func:`_indices`; also at the top
    level, kept for compatibility); docs/outputs.md, ``section.*``."""
    return {"window": SECTION_WINDOW, **res.section_speed, **speed_oscillation(res),
            "speed_wave": speed_wave(res), "waves": waves_summary(res, *_blocks(res)),
            "deviation": deviation_summary(res), "inlet": inlet_summary(res), **micro}


def inlet_summary(res: CoSimResult) -> dict[str, float]:
    """The state SUMO holds at the section's inlet, the window means of the first Edie cell
    per class (veh/km, km/h; NaN without a vehicle of the class): what sits upstream of
    x = 0 reaches the section only through this state."""
    first = res.micro[:, :, 0]
    mean = {name: float(np.nanmean(first[:, k])) if np.isfinite(first[:, k]).any()
            else float("nan") for k, name in enumerate(VARIABLES)}
    return {"rho_h_veh_km": float(veh_m_to_veh_km(mean["rho_h"])),
            "v_h_kmh": float(ms_to_kmh(mean["v_h"])),
            "rho_a_veh_km": float(veh_m_to_veh_km(mean["rho_a"])),
            "v_a_kmh": float(ms_to_kmh(mean["v_a"]))}


def deviation_summary(res: CoSimResult) -> dict[str, Any] | None:
    """The window's deviation from the warm-up's stationary state
    (:mod:`arzsumo.evaluation.decay`); None without a reference."""
    if res.stationary is None or res.t.size < 2:
        return None
    e = deviation_norm(res.micro, res.stationary)
    return decay(res.t, e, res.stationary_band, res.sumo.control_period).as_dict()


#: ``summary.json["meter"]``: keys of the meter's own summary kept there (control window)
METER_KEYS = ("mode", "clearance_s", "release_rate", "releases", "greens",
              "releases_per_green_max", "override_steps", "override_s", "ramp_storage",
              "emergency_stops", "emergency_braking", "speed_limit_changes",
              "speed_limit_m_s", "speed_limit_nominal_m_s")


def meter_summary(res: CoSimResult) -> dict[str, Any]:
    """``summary.json["meter"]``: the meter's realisation and its counts over the control
    window (docs/outputs.md, ``meter.*``)."""
    return {k: res.meter.get(k) for k in METER_KEYS}


def finite_variance(values: np.ndarray) -> float:
    """``numpy.nanvar`` of ``values`` (m^2/s^2 here); NaN, without numpy's "Degrees of
    freedom <= 0" warning, when every value is NaN (no vehicle of the class sampled)."""
    values = np.asarray(values, float)
    return float(np.nanvar(values)) if (~np.isnan(values)).any() else float("nan")


def summary(res: CoSimResult) -> RunSummary:
    """The run's summary: meter counts, events, indices (micro and twins), fidelity, accounting.

    Meter counts (``plan_changes``, ``light_changes``, ``max_ramp_queue``) cover the
    control window; the warm-up's are under ``warmup`` (:func:`warmup_summary`).
    """
    per, rep, net = res.periods, res.report, res.network
    triggered = per["triggered"].astype(bool)
    horizon = float(res.sumo.horizon)
    log = res.controller_log
    n = triggered.size
    v = res.micro[:, [1, 3]]
    micro = _indices(res, res.micro)
    counts = WindowCounts(
        plan_changes=int(res.meter["plan_changes"]),
        light_changes=int(res.meter["light_changes"]), triggers=int(triggered.sum()),
        release_time=release_time(list(log.t[:n]), list(log.triggered[:n]), horizon),
        max_ramp_queue=int(res.meter["max_queue"]))
    accounting = Accounting(rep.inserted, rep.requested, rep.delivered_main, rep.waiting,
                            rep.arrived, rep.teleports, rep.collisions,
                            rep.emergency_braking, rep.standstill_main_s) if rep \
        else Accounting()
    return RunSummary(
        identity=RunIdentity(res.scenario.name, res.scenario.source, __version__,
                             res.sumo.seed, res.settings.controller),
        equilibrium=res.equilibrium.as_dict(),
        lambda_4=float(linearize(res.equilibrium).eigenvalues[3]),
        q_nominal=res.q_nominal, horizon=horizon, warmup=warmup_summary(res), counts=counts,
        meter=meter_summary(res),
        speed_variance={"h": finite_variance(v[:, 0]), "a": finite_variance(v[:, 1])},
        micro=micro, section=section_summary(res, micro),
        network=net.window if net else None,
        network_whole_run=net.whole_run if net else None,
        network_whole_demand=net.whole_demand if net else None,
        twin_replay=_indices(res, res.replay), twin_reference=_indices(res, res.reference),
        rmse={"replay": rmse(res, res.replay), "reference": rmse(res, res.reference)},
        rmse_blocks=rmse_blocks(res), section_trend=section_trend(res),
        estimation=estimation_summary(res), actuation=actuation_summary(res),
        twin_status=res.twin_status, accounting=accounting, placement=res.placement,
        wall_time=res.wall_time, timings=res.timings,
        controller_time_per_period=float(np.mean(per["controller_s"])) if n else None,
        settings=res.settings.as_dict(), disturbance=res.disturbance)


#: ``periods.parquet`` column -> the event trigger's diagnostic in the controller's log
TRIGGER_TERMS = {"trigger_energy": "V", "trigger_hold_error": "d", "trigger_memory": "m"}


def trigger_terms(log: ControlLog, n: int) -> dict[str, np.ndarray]:
    """The event trigger's terms at each of the first ``n`` checks (defdynamic): the
    Lyapunov energy V of the state, the hold error d and the dynamic variable m, in the
    design's scaled units (:mod:`arzsumo.control.etc`); NaN for a law without a trigger."""
    logged = {column: np.asarray(log.extra.get(key, ()), float)[:n]
              for column, key in TRIGGER_TERMS.items()}
    return {column: np.pad(v, (0, n - v.size), constant_values=np.nan)
            for column, v in logged.items()}


def periods_table(res: CoSimResult) -> pa.Table:
    cols = {"t_s": res.periods["t"]}
    cols.update({k: v for k, v in res.periods.items() if k not in ("t", "controller_s")})
    for flag in ("triggered", "saturated", "rate_limited", "override"):
        cols[flag] = res.periods[flag].astype(bool)
    cols.update(trigger_terms(res.controller_log, len(cols["t_s"])))
    return with_units(pa.table(cols), PERIODS, "periods")


def cells_table(res: CoSimResult) -> pa.Table:
    parts = []
    n_t, _, n_x = res.micro.shape
    for source, arr in (("micro", res.micro), ("replay", res.replay),
                        ("reference", res.reference)):
        cols: dict[str, Any] = {"source": np.full(n_t * n_x, source),
                                "t_s": np.repeat(res.t, n_x), "x_m": np.tile(res.x, n_t)}
        cols.update({name: arr[:, k, :].ravel() for k, name in enumerate(VARIABLES)})
        parts.append(pa.table(cols))
    return with_units(pa.concat_tables(parts), CELLS, "cells")


def write_results(res: CoSimResult, out: str | Path | OutputDir, scenario_text: str,
                  plots: bool = True, overwrite: bool = False,
                  summ: RunSummary | None = None) -> tuple[Path, dict[str, Any]]:
    """Write everything into ``out`` atomically (a previous ``run`` result there is replaced
    only with ``overwrite``, see :mod:`arzsumo.outdir`); return the path and summary
    (``summ``: the run's summary when computed already)."""
    from arzsumo.outputs.figures import save_figures
    from arzsumo.plots.bridge import bridge_figures

    summ = (summ if summ is not None else summary(res)).to_dict()
    with atomic_dir(out, "run", overwrite=overwrite) as tmp:
        pq.write_table(periods_table(res), tmp / "periods.parquet")
        pq.write_table(cells_table(res), tmp / "cells.parquet")
        (tmp / "scenario.toml").write_text(scenario_text, encoding="utf-8")
        (tmp / "summary.json").write_text(json.dumps(json_safe(summ), indent=2) + "\n",
                                          encoding="utf-8")
        pd.DataFrame([row_of(summ)]).to_csv(tmp / SUMMARY_CSV, index=False)
        if res.network is not None:
            (tmp / TRIPINFO_GZ).write_bytes(res.network.tripinfo_gz)
        if res.files is not None:   # linked or copied in chunks, never read into memory
            res.files.place(tmp)
        if plots:
            waves = summ["section"]["speed_wave"]
            save_figures(bridge_figures(res, {c: waves[c]["speed_kmh"] for c in ("h", "a")}),
                         tmp, dpi=100)
    return target_of(out), summ
