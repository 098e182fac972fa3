"""``arzsumo premise``: the premise gates of a scenario, measured on its open-loop runs.

:func:`run_premise` runs the premise runs of every seed (:mod:`.premise_runs`: a
baseline, a paired pulse and a release-rate staircase per seed, one task each on the
sweep engine's local pool or a Dask cluster, stored resumably in ``OUT/runs``), then
:func:`analyse` computes every gate of :mod:`arzsumo_studies.gates` per seed and the
verdict over seeds:

* ``coupling[c]`` from the baseline's lateral snapshots (computed in the worker);
* ``waves[c]`` and ``model_wave[c]`` on the baseline's speed field per class (50 m x one
  control period), against the model's lambda_4 at the scenario's equilibrium;
* ``amplification[c]`` on the baseline's block speeds (100 m x 10 s);
* ``pulse``: pulse against baseline on the same seed, t0 the window's start, the round
  trip T = L / min(lambda_1, lambda_3) + L / |lambda_4| (the paper's t_f; or
  ``round_trip``), D smoothed over ``smooth_s``, against a noise floor (:func:`floors`);
* ``actuator`` on the seed's staircase (and, reported apart, pooled over the seeds);
* ``stationary`` (the baseline's section count, 30 s blocks), ``inserted`` (SUMO's
  mainline insertions against its requests, warm-up and window), ``ramp_demand`` (the
  ramp demand against ``release_rate_max``; one vehicle per green only: a fixed cycle has
  no rate bound) and ``ramp_queue`` (the window's largest ramp queue against the storage).

A class without vehicles (fewer than two lateral samples) is not measured. SI units.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.evaluation.fields import block_means
from arzsumo.evaluation.stationarity import count_trend
from arzsumo.scenario import Scenario
from arzsumo_studies.gates import (
    ActuatorRecord,
    GateResult,
    PremiseError,
    PremiseThresholds,
    PremiseVerdict,
    actuator_gate,
    amplification_gate,
    inserted_gate,
    model_wave_gate,
    premise_verdict,
    pulse_gate,
    ramp_demand_gate,
    ramp_queue_gate,
    round_trip_time,
    stationarity_gate,
    wave_gate,
)
from arzsumo_studies.measures.car_following_stability import StringPrediction, predict
from arzsumo_studies.premise.floors import (
    _array,
    class_fields,
    classes_of,
    deviation_norms,
    floors,
)
from arzsumo_studies.premise.pooled import held_seeds, pooled_pulse
from arzsumo_studies.premise.runs import KINDS, PremiseOptions, premise_runs

#: blocks of the amplification gate: s and m
BLOCK_S, BLOCK_M = 10.0, 100.0
#: margin of the default window beyond two round trips, s (the 30 s smoothing's edge)
WINDOW_MARGIN_S = 60.0
#: the shortest window: three 30 s blocks of the count trend, s
MIN_WINDOW_S = 90.0


@dataclass(frozen=True)
class ModelSpeeds:
    """The model's characteristic speeds at the scenario's equilibrium (m/s) and the
    round trip they give, T = L / min(lambda_1, lambda_3) + L / |lambda_4| (s)."""

    lambda_4: float
    v_down: float
    round_trip: float


def model_speeds(sc: Scenario) -> ModelSpeeds:
    """:class:`ModelSpeeds` of ``sc`` (its ``[equilibrium]``)."""
    from arzsumo.model.characteristic import linearize

    ev = linearize(sc.equilibrium).eigenvalues
    v_down, lam4 = float(min(ev[0], ev[2])), float(ev[3])
    return ModelSpeeds(lam4, v_down, round_trip_time(sc.params.length, v_down, lam4))


def default_window(sc: Scenario, round_trip: float,
                   th: PremiseThresholds | None = None) -> float:
    """The baseline's and pulse's window, s: the longest of ``[sumo] horizon_s``,
    :data:`MIN_WINDOW_S` and the pulse gate's two round trips plus
    :data:`WINDOW_MARGIN_S` (in whole control periods)."""
    th = th or PremiseThresholds()
    need = th.pulse_round_trips * round_trip + WINDOW_MARGIN_S
    period = sc.sumo.control_period
    return max(sc.sumo.horizon, MIN_WINDOW_S, math.ceil(need / period - 1e-9) * period)


@dataclass(frozen=True)
class AnalysisOptions:
    """How the rows are judged: ``round_trip`` (s, None: the model's), ``smooth`` (s, the
    pulse's moving mean) and ``floor`` (one of :data:`.floors.FLOORS`)."""

    round_trip: float | None = None
    smooth: float = 30.0
    floor: str = "auto"


@dataclass(frozen=True)
class PremiseReport:
    """The gates per seed, the verdict, and what the figure and the files show.

    ``gates``: per seed its GateResults; ``pooled_actuator``: the actuator gate on the
    staircases of the seeds that held their demand (:func:`.pooled.held_seeds`), pooled;
    ``floors``: per seed the pulse floors (m/s m^(1/2), per class
    and ``total``) and ``floor_method``; ``runs``: per seed its accounting (wall times,
    samples, collisions); ``pulse_series``: per seed (t - t0 s, D_total, D_total
    smoothed, floor, window s); ``staircases``: per seed (t s, q veh/s, r veh/s, step times s).
    """

    seeds: tuple[int, ...]
    gates: Mapping[int, list[GateResult]]
    verdict: PremiseVerdict
    pooled_actuator: GateResult
    model: ModelSpeeds
    round_trip: float
    floor_method: str
    floors: Mapping[int, Mapping[str, float]]
    runs: Mapping[int, Mapping[str, Any]]
    pulse_series: Mapping[int, tuple[Any, ...]] = field(default_factory=dict)
    staircases: Mapping[int, tuple[Any, ...]] = field(default_factory=dict)
    #: per seed and class the linear string-stability prediction at the baseline's
    #: measured operating point
    #: (:func:`arzsumo_studies.measures.car_following_stability.predict`), the theory
    #: beside the measured amplification and pulse
    theory: Mapping[int, Mapping[str, StringPrediction]] = field(default_factory=dict)
    #: the pulse's mean response over the seeds that held the operating point
    #: (:func:`arzsumo_studies.premise.pooled.pooled_pulse`); None in older reports
    pooled_pulse: GateResult | None = None


def gate_from_dict(d: Mapping[str, Any]) -> GateResult:
    """A GateResult from its :meth:`~GateResult.as_dict` (after JSON: None is NaN)."""
    thr = d["threshold"]
    thr = tuple(float(v) for v in thr) if isinstance(thr, list) else float(thr)
    value = math.nan if d["value"] is None else float(d["value"])
    return GateResult(d["name"], value, thr, bool(d["passed"]), dict(d["detail"]))


def speed_gates(base: Mapping[str, Any], classes: Sequence[str], model: ModelSpeeds | None,
                 length: float, th: PremiseThresholds) -> list[GateResult]:
    """coupling, waves, model_wave (unless ``model`` is None) and amplification of each
    class."""
    dt, dx = float(base["period_s"]), float(base["dx_m"])
    fields = class_fields(base, classes)
    gates = [gate_from_dict(d) for d in base["coupling"]]
    waves = [wave_gate(fields[c], dt, dx, c, th) for c in classes]
    gates += waves
    if model is not None:
        gates += [model_wave_gate(model.lambda_4, w.value, c, th)
                  for c, w in zip(classes, waves, strict=True)]
    bt, bx = max(1, round(BLOCK_S / dt)), max(1, round(BLOCK_M / dx))
    for c in classes:
        blocks = block_means(fields[c][:, None, :], bt, bx)[:, 0, :]
        x = (np.arange(blocks.shape[1]) + 0.5) * bx * dx
        gates.append(amplification_gate(blocks, x, length, c, th))
    return gates


def operating_gates(base: Mapping[str, Any], th: PremiseThresholds) -> list[GateResult]:
    """stationary, inserted, ramp_demand (one per green) and ramp_queue."""
    trend = count_trend(_array(base["count_veh"]), float(base["period_s"]))
    gates = [stationarity_gate(trend),
             inserted_gate(base["inserted_main"], max(base["requested_main"], 1), th)]
    if base["max_release_veh_s"] is not None:
        gates.append(ramp_demand_gate(base["ramp_demand_veh_s"], base["max_release_veh_s"]))
    gates.append(ramp_queue_gate(base["max_queue_veh"], base["ramp_storage_veh"]))
    return gates


def actuator_record(stair: Mapping[str, Any]) -> ActuatorRecord:
    """The staircase run as the actuator gate's record."""
    return ActuatorRecord(_array(stair["t_s"]), _array(stair["q_veh_s"]),
                          _array(stair["r_veh_s"]), tuple(stair["step_times_s"]))


def read_pulse(base: Mapping[str, Any], pulse: Mapping[str, Any], classes: Sequence[str],
               round_trip: float, floor: Mapping[str, float], th: PremiseThresholds,
               smooth: float) -> GateResult:
    """The pulse gate on a seed's baseline and pulse rows; unmeasured (NaN, failed, the
    reason in its detail) where the pulse run has no deviation to read (a class that
    left the section during the pulse)."""
    try:
        return pulse_gate(_array(base["t_s"]), class_fields(base, classes),
                          class_fields(pulse, classes), float(base["dx_m"]),
                          float(base["t0_s"]), round_trip, floor, th, smooth)
    except PremiseError as exc:
        return GateResult("pulse", math.nan, th.pulse_round_trips * round_trip, False,
                          {"round_trip_s": round_trip, "reason": str(exc)})


def seed_gates(runs: Mapping[str, Mapping[str, Any]], floor: Mapping[str, float],
               model: ModelSpeeds, round_trip: float, length: float, smooth: float,
               th: PremiseThresholds) -> list[GateResult]:
    """Every gate of one seed from its ``baseline``, ``pulse`` and ``staircase`` rows."""
    base, pulse = runs["baseline"], runs["pulse"]
    classes = classes_of(base)
    gates = speed_gates(base, classes, model, length, th)
    gates.append(read_pulse(base, pulse, classes, round_trip, floor, th, smooth))
    gates.append(actuator_gate(actuator_record(runs["staircase"]), th))
    return gates + operating_gates(base, th)


def _series(runs: Mapping[str, Mapping[str, Any]], floor: Mapping[str, float],
            window: float, smooth: float) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
    """The figure's series of one seed: (t - t0, D, D smoothed, floor, window) of the
    pulse and (t, q, r, step times) of the staircase (s, m/s m^(1/2), veh/s)."""
    from arzsumo_studies.gates.instability import smoothed

    base, pulse, stair = runs["baseline"], runs["pulse"], runs["staircase"]
    cls = classes_of(base)
    d = deviation_norms(class_fields(base, cls), class_fields(pulse, cls),
                        float(base["dx_m"]))["total"]
    t = _array(base["t_s"]) - float(base["t0_s"])
    return ((t, d, smoothed(t, d, smooth), float(floor.get("total", 0.0)), window),
            (_array(stair["t_s"]), _array(stair["q_veh_s"]), _array(stair["r_veh_s"]),
             _array(stair["step_times_s"])))


def theory_at(base: Mapping[str, Any], sc: Scenario) -> dict[str, StringPrediction]:
    """The prediction at a baseline's mean class densities and HV speed ({} for a row
    that does not carry the densities, or whose HVs stood still: a deadlocked run has no
    operating point to linearise about)."""
    if "rho_hv_veh_m" not in base or "rho_av_veh_m" not in base:
        return {}
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)      # an all-NaN field
        v = float(np.nanmean(class_fields(base, ["hv"])["hv"]))
    if not (math.isfinite(v) and v > 0.0):
        return {}
    return predict(sc.params, sc.sumo, float(base["rho_hv_veh_m"]),
                   float(base["rho_av_veh_m"]), v)


def _accounting(runs: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    base = runs["baseline"]
    return {"wall_s": {k: runs[k]["wall_s"] for k in KINDS},
            "warmup_wall_s": runs["baseline"].get("warmup_wall_s"),
            "lateral_samples": base["lateral_samples"],
            "main_vehicles_total": int(sum(base["main_vehicles"])),
            "class_samples": dict(base["class_samples"]), "collisions": base["collisions"],
            "meter_mode": base["meter_mode"], "pulse_plan": runs["pulse"]["pulse_plan"]}


def analyse(rows: Sequence[Mapping[str, Any]], sc: Scenario, opts: AnalysisOptions,
            th: PremiseThresholds | None = None) -> PremiseReport:
    """The :class:`PremiseReport` of the rows of :func:`run_premise_task` (every kind of
    every seed)."""
    th = th or PremiseThresholds()
    by_seed: dict[int, dict[str, Mapping[str, Any]]] = {}
    for r in rows:
        by_seed.setdefault(int(r["seed"]), {})[r["kind"]] = r
    model = model_speeds(sc)
    trip = opts.round_trip or model.round_trip
    held = held_seeds(by_seed)
    method, floor = floors(by_seed, opts.floor, held)
    seeds = tuple(sorted(by_seed))
    gates = {s: seed_gates(by_seed[s], floor[s], model, trip, sc.params.length,
                           opts.smooth, th) for s in seeds}
    pooled = (actuator_gate([actuator_record(by_seed[s]["staircase"]) for s in held], th)
              if held else GateResult("actuator", math.nan, th.gain_range, False,
                                      {"reason": "no seed held its demand"}))
    pooled = GateResult(pooled.name, pooled.value, pooled.threshold, pooled.passed,
                        {**pooled.detail, "seed_list": list(held)})
    pulse_mean = pooled_pulse(by_seed, held, floor, trip, opts.smooth, th)
    series = {s: _series(by_seed[s], floor[s], th.pulse_round_trips * trip, opts.smooth)
              for s in seeds}
    return PremiseReport(seeds, gates, premise_verdict([gates[s] for s in seeds], th),
                         pooled, model, trip, method, floor,
                         {s: _accounting(by_seed[s]) for s in seeds},
                         {s: v[0] for s, v in series.items()},
                         {s: v[1] for s, v in series.items()},
                         {s: theory_at(by_seed[s]["baseline"], sc) for s in seeds},
                         pulse_mean)


def run_premise(path: Path, sc: Scenario, seeds: Sequence[int], warmup: float,
                opts: PremiseOptions, analysis: AnalysisOptions, out: Path, *,
                workers: int | None = None, scheduler: str | None = None,
                progress: bool = True) -> PremiseReport:
    """Run (or read from ``out/runs``) the premise runs of ``seeds`` and analyse them: a
    seed's runs share one warm-up (:func:`~arzsumo_studies.premise.runs.grouped`).

    ``path`` is the scenario file of ``sc``; ``warmup`` s; ``out`` the claimed output
    directory; ``workers``/``scheduler`` as :func:`~arzsumo_studies.design.run_design`.
    """
    from arzsumo_studies.design import run_design
    from arzsumo_studies.premise.runs import grouped, run_premise_group, ungrouped

    runs = grouped(premise_runs(path, list(seeds), warmup, opts))
    rows = run_design(runs, run_premise_group, out, workers=workers, scheduler=scheduler,
                      progress=progress, label="premise")
    return analyse(ungrouped(rows), sc, analysis)


def check_window(window: float, round_trip: float, trip_given: bool,
                 th: PremiseThresholds | None = None) -> None:
    """Refuse a window the gates cannot use: shorter than 3 blocks of the count trend
    (90 s) or than the pulse gate's two round trips after the pulse (t0: its start)."""
    from arzsumo_studies.premise.runs import PremiseRunError

    th = th or PremiseThresholds()
    pulse = th.pulse_round_trips * round_trip
    if window >= max(MIN_WINDOW_S, pulse) - 1e-9:
        return
    if pulse <= MIN_WINDOW_S:
        raise PremiseRunError(f"--window = {window:g} is not allowed: the count trend needs "
                              f"3 blocks of 30 s; allowed: at least {MIN_WINDOW_S:g} s")
    where = ("--round-trip" if trip_given else "the model's L / min(lambda_1, lambda_3) + "
             "L / |lambda_4| at the scenario's equilibrium")
    raise PremiseRunError(
        f"--window = {window:g} is not allowed: the pulse gate reads the record up to "
        f"{th.pulse_round_trips:g} round trips after the pulse, {th.pulse_round_trips:g} x "
        f"{round_trip:.4g} s (T: {where}); allowed: at least {pulse:.6g} s, or a shorter "
        "--round-trip")


def report_document(report: PremiseReport, sc: Scenario, path: Path, scenario_text: str,
                    warmup: float, opts: PremiseOptions,
                    analysis: AnalysisOptions) -> dict[str, Any]:
    """``premise.json``: every GateResult per seed, the verdict, the pooled actuator,
    the options, the model's speeds, the floors, the runs' accounting, the scenario."""
    from arzsumo.version import __version__

    m = report.model
    return {
        "kind": "premise", "version": __version__,
        "scenario": {"name": sc.name, "file": str(path), "toml": scenario_text},
        "seeds": list(report.seeds),
        "options": {"warmup_s": warmup, **opts.as_dict(), "smooth_s": analysis.smooth,
                    "floor": analysis.floor, "round_trip_s": analysis.round_trip},
        "model": {"lambda_4_ms": m.lambda_4, "v_down_ms": m.v_down,
                  "round_trip_model_s": m.round_trip, "round_trip_s": report.round_trip},
        "pulse_floor": {"method": report.floor_method,
                        "per_seed": {str(s): dict(v) for s, v in report.floors.items()}},
        "per_seed": [{"seed": s, "gates": [g.as_dict() for g in report.gates[s]]}
                     for s in report.seeds],
        "pooled": {"actuator": report.pooled_actuator.as_dict(),
                   **({"pulse_mean": report.pooled_pulse.as_dict()}
                      if report.pooled_pulse is not None else {})},
        "verdict": report.verdict.as_dict(),
        "runs": {str(s): dict(v) for s, v in report.runs.items()},
        "theory": {str(s): {c: asdict(p) for c, p in v.items()}
                   for s, v in report.theory.items()},
    }
