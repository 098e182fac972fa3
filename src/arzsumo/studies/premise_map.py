"""Where the paper's premise holds in SUMO: the premise gates over what the mission leaves
free on the SUMO side (``arzsumo study premise-map``).

The frame stays fixed (1 km, one 6.5 m lane under the sublane model, HV and AV types,
the ramp meter at the outlet). Each :class:`MapPoint` changes a few ``[sumo]`` keys of
the base scenario: the lateral behaviour, the HVs' car following, the downstream
bottleneck, the AV share and the demand (:data:`POINTS`). The car-following points
are first mapped to their own discharge (two discharge runs on a seed no gate reads:
:mod:`arzsumo.studies.premise_map_points`); a point that gridlocks there is left out.
Per point and seed an
open-loop baseline (:mod:`arzsumo.studies.premise_runs`), and on the point's first seed
the paired pulse; then the gates of ``arzsumo premise`` that these runs decide:

* coupling and waves per class, amplification per class (the baseline);
* the pulse, with the round trip L / v + L / |c| of the *measured* HV speed v and
  upstream wave speed c (the model is identified only where the map points), and the
  floor of two seeds' baselines (chance alone); with one seed the gate is left
  undecided (its reading against the pulse's own late deviation is kept in its detail);
* stationary, inserted, ramp demand and ramp queue (the operating point).

The actuator's staircase and the model's gates are left to ``arzsumo premise`` on the
point the map selects: the staircase costs four times a baseline, and the model is
identified there. Outputs: ``premise_map.csv`` (one row per point, seed and gate),
``premise_map_points.csv`` (per point: the share of seeds each gate passed on, the
measured speeds, densities and outflow, the linear string-stability prediction at the
measured operating point and the mapped discharge) and ``premise_map.png``.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.evaluation.premise import GateResult, PremiseThresholds
from arzsumo.evaluation.premise.instability import round_trip_time
from arzsumo.evaluation.premise.queue_tail import queue_tail
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.premise_map import write_map
from arzsumo.outputs.studies import markdown_table, publish
from arzsumo.scenario import Scenario
from arzsumo.studies.common import (
    FORMER_DEFAULT,
    StudyError,
    add_output,
    add_runs,
    plots_wanted,
    print_list,
    shipped_scenario,
    study_spec,
)
from arzsumo.studies.design import StudyRun, design_runs, run_design
from arzsumo.studies.premise import (
    LATE_SHARE,
    class_fields,
    classes_of,
    deviation_norms,
    model_speeds,
    operating_gates,
    read_pulse,
    speed_gates,
    theory_at,
)
from arzsumo.studies.premise_map_points import (
    COUPLED,
    MAPPING_SEED,
    NAME,
    POINTS,
    MapPoint,
    discharge_runs,
    discharge_task,
    flowing,
    mapped_points,
    mapping_lines,
)
from arzsumo.studies.premise_runs import (
    PremiseOptions,
    grouped,
    horizon_periods,
    run_premise_group,
    ungrouped,
)
from arzsumo.units import VEH_H_PER_VEH_S, VEH_KM_PER_VEH_M, ms_to_kmh

#: the results page this study keeps a block of
PAGE = "premise_map"
#: the gates the map decides, in the order of its table and figure
MAP_GATES = ("coupling[hv]", "coupling[av]", "waves[hv]", "waves[av]",
             "amplification[hv]", "amplification[av]", "pulse", "stationary", "inserted",
             "ramp_queue")


# -- the design ----------------------------------------------------------------------------
def map_runs(path: Path, points: Sequence[MapPoint], seeds: Sequence[int], warmup: float,
             opts: PremiseOptions, pulses: bool = True) -> list[StudyRun]:
    """Per point and seed its baseline, and (with ``pulses``) on the first seed its pulse:
    IDs ``point=P,seed=S,kind=K``."""
    runs = []
    for p in points:
        spec = study_spec(NAME, path, seeds=list(seeds),
                          set={"run.warmup_s": float(warmup), **p.set})
        for r in design_runs(spec):
            first = pulses and r.columns["seed"] == seeds[0]
            kinds = ("baseline", "pulse") if first else ("baseline",)
            n = horizon_periods(opts, r)
            runs += [replace(r, run_id=f"point={p.name},{r.run_id},kind={k}",
                             columns={"point": p.name, "axis": p.axis, **r.columns},
                             options={**opts.for_kind(k), "horizon_periods": n})
                     for k in kinds]
    return runs


# -- the analysis (pure) -------------------------------------------------------------------
def measured_round_trip(base: Mapping[str, Any], gates: Sequence[GateResult],
                        length: float) -> float:
    """L / v + L / |c| (s) of the baseline's mean HV speed v and its HV wave speed c;
    NaN when the HV waves were not measured travelling upstream."""
    wave = next((g for g in gates if g.name == "waves[hv]"), None)
    v = float(np.nanmean(class_fields(base, ["hv"])["hv"]))
    if wave is None or not math.isfinite(wave.value) or wave.value >= 0 or not v > 0:
        return math.nan
    return round_trip_time(length, v, wave.value)


def point_gates(rows: Mapping[int, Mapping[str, Mapping[str, Any]]], length: float,
                th: PremiseThresholds, smooth: float, fallback_trip: float
                ) -> dict[int, list[GateResult]]:
    """The map's gates per seed of one point (``rows``: seed -> kind -> row); the pulse's
    round trip is :func:`measured_round_trip`, else ``fallback_trip`` (s)."""
    seeds = sorted(rows)
    floor = _floor(rows)
    out: dict[int, list[GateResult]] = {}
    for s in seeds:
        base = rows[s]["baseline"]
        cls = classes_of(base)
        gates = speed_gates(base, cls, None, length, th)
        if "pulse" in rows[s]:
            trip = measured_round_trip(base, gates, length)
            pulse = _pulse(base, rows[s]["pulse"], cls,
                           trip if math.isfinite(trip) else fallback_trip, floor, th, smooth)
            if len(seeds) < 2:
                pulse = _undecided(pulse)
            gates.append(pulse)
        out[s] = gates + operating_gates(base, th)
    return out


def _floor(rows: Mapping[int, Mapping[str, Mapping[str, Any]]]) -> dict[str, float]:
    """The pulse's floor (m/s m^(1/2)): the median distance of two seeds' baselines
    (chance alone), or with one seed the median of the pulse's own deviation over the
    record's last quarter (``arzsumo premise --floor late``), which leaves the gate
    undecided (:func:`_undecided`)."""
    seeds = sorted(rows)
    a = rows[seeds[0]]["baseline"]
    if len(seeds) >= 2:
        b = rows[seeds[1]]["baseline"]
    elif "pulse" in rows[seeds[0]]:
        b = rows[seeds[0]]["pulse"]
    else:
        return {}
    cls = [c for c in classes_of(a) if c in classes_of(rows[seeds[-1]]["baseline"])]
    d = deviation_norms(class_fields(a, cls), class_fields(b, cls), float(a["dx_m"]))
    start = 0 if len(seeds) >= 2 else int(len(d["total"]) * (1 - LATE_SHARE))
    return {k: float(np.nanmedian(v[start:])) for k, v in d.items()}


def _undecided(pulse: GateResult) -> GateResult:
    """The pulse gate of a single seed, kept as a reading but not decided: the late floor
    cannot tell a pulse that grows from two runs that drift apart by chance (on SUMO's
    streams the paired deviation grows to the chance level within a few minutes)."""
    return GateResult("pulse", math.nan, pulse.threshold, False,
                      {**pulse.detail, "late_floor_value": pulse.value,
                       "reason": "one seed: no floor of chance (two baselines) to decide "
                                 "against"})


def _pulse(base: Mapping[str, Any], pulse: Mapping[str, Any], cls: Sequence[str],
           trip: float, floor: Mapping[str, float], th: PremiseThresholds,
           smooth: float) -> GateResult:
    """The pulse gate; unmeasured (NaN, failed) when the window ends before the gate's
    round trips after the pulse."""
    t, t0 = np.array(base["t_s"], dtype=float), float(base["t0_s"])
    need = t0 + th.pulse_round_trips * trip
    if t[-1] < need:
        return GateResult("pulse", math.nan, th.pulse_round_trips * trip, False,
                          {"round_trip_s": trip, "window_s": float(t[-1] - t0),
                           "reason": "the window ends before the gate's round trips"})
    return read_pulse(base, pulse, cls, trip, floor, th, smooth)


def point_measures(rows: Mapping[int, Mapping[str, Mapping[str, Any]]]) -> dict[str, float]:
    """The baselines' means over seeds: class speeds (km/h), densities (veh/km) and the
    mainline outflow q(L) (veh/h); and the largest queue tail over seeds (m: the free
    stretch from x = 0, :func:`~arzsumo.evaluation.premise.queue_tail.queue_tail`; the
    amplification of a seed with a tail reads the passage from free to congested
    traffic, not a wave's growth)."""
    base = [r["baseline"] for r in rows.values()]

    def mean(key: str) -> float:    # stored rows hold NaN as None
        per_run = [np.array(b.get(key, math.nan), dtype=float) for b in base]
        means = [float(np.nanmean(a)) for a in per_run if np.isfinite(a).any()]
        return float(np.mean(means)) if means else math.nan

    out = {}
    for c in ("hv", "av"):
        out[f"v_{c}_kmh"] = float(ms_to_kmh(mean(f"v_{c}")))
        out[f"rho_{c}_veh_km"] = mean(f"rho_{c}_veh_m") * VEH_KM_PER_VEH_M
    out["q_out_veh_h"] = mean("outflow_veh_s") * VEH_H_PER_VEH_S
    out["queue_tail_m"] = max(queue_tail(np.array(b["x_m"], float),
                                         np.array(b["v_hv"], float)) for b in base)
    return out


def point_theory(rows: Mapping[int, Mapping[str, Mapping[str, Any]]], sc: Scenario
                 ) -> dict[str, float]:
    """The linear string-stability prediction at each seed's measured operating point
    (:func:`~arzsumo.studies.premise.theory_at`), averaged over seeds: per class the
    largest gain per vehicle ``gain_*`` and the growth over the section's vehicles
    ``growth_*`` (NaN for a model without one, e.g. Krauss)."""
    preds = [theory_at(r["baseline"], sc) for r in rows.values()]
    out = {}
    for c in ("hv", "av"):
        for key, attr in (("gain", "gain"), ("growth", "growth")):
            vals = [getattr(p[c], attr) for p in preds if c in p]
            out[f"{key}_{c}"] = float(np.mean(vals)) if vals else math.nan
    return out


def map_tables(rows: Sequence[Mapping[str, Any]], points: Sequence[MapPoint], length: float,
               fallback_trip: float, th: PremiseThresholds | None = None,
               smooth: float = 30.0, scenarios: Mapping[str, Scenario] | None = None
               ) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(per point, seed and gate; per point) of the rows of :func:`map_runs`' runs, in
    the order of ``points``; ``fallback_trip``: the pulse's round trip (s) where the HV
    waves were not measured travelling upstream; ``scenarios`` (point name -> its
    resolved scenario): the theory's columns (:func:`point_theory`)."""
    th = th or PremiseThresholds()
    by: dict[str, dict[int, dict[str, Mapping[str, Any]]]] = {}
    for r in rows:
        by.setdefault(r["point"], {}).setdefault(int(r["seed"]), {})[r["kind"]] = r
    long, wide = [], []
    for p in points:
        if p.name not in by:
            continue
        gates = point_gates(by[p.name], length, th, smooth, fallback_trip)
        row: dict[str, Any] = {"point": p.name, "axis": p.axis,
                               "changes": "; ".join(f"{k[5:]} = {v}" for k, v in p.set.items()
                                                    if k[5:] not in COUPLED
                                                    or COUPLED[k[5:]] != v),
                               "seeds": len(gates)}
        for s, gs in gates.items():
            long += [{"point": p.name, "seed": s, "gate": g.name, "value": g.value,
                      "threshold": str(g.threshold), "passed": bool(g.passed)} for g in gs]
        for name in MAP_GATES:
            found = [g for gs in gates.values() for g in gs if g.name == name]
            decided = [g for g in found if "late_floor_value" not in g.detail]
            row[f"{name}_value"] = float(np.nanmean([g.value for g in found])) \
                if found and any(math.isfinite(g.value) for g in found) else math.nan
            # a gate left undecided (one seed's pulse) is no pass and no fail: NaN
            row[f"{name}_passed"] = float(np.mean([g.passed for g in decided])) \
                if decided else math.nan
        theory = point_theory(by[p.name], scenarios[p.name]) \
            if scenarios and p.name in scenarios else {}
        wide.append({**row, **point_measures(by[p.name]), **theory})
    return pd.DataFrame(long), pd.DataFrame(wide)


# -- the command ---------------------------------------------------------------------------
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The premise map's options."""
    parser.add_argument("--scenario", type=Path, metavar="SCENARIO.toml",
                        help="base scenario every point changes (default: the former "
                             "default, lateral_files)")
    parser.add_argument("--points", default=None, metavar="LIST",
                        help="comma-separated point names (default: all: "
                             + ", ".join(p.name for p in POINTS) + ")")
    parser.add_argument("--window", type=float, default=540.0,
                        help="baseline and pulse window after the warm-up, s")
    parser.add_argument("--pulse-s", type=float, default=25.0,
                        help="the pulse: the meter at its least plan this long, s")
    parser.add_argument("--no-pulse", action="store_true",
                        help="baselines only (the pulse gate is then not measured)")
    add_runs(parser, seeds="1,2")
    add_output(parser, NAME, PAGE)
    parser.add_argument("--page", default=PAGE, metavar="NAME",
                        help=f"the results page --docs regenerates, DIR/NAME.md (default: "
                             f"{PAGE}; e.g. premise_map_car_following for that axis)")


def selected_points(text: str | None) -> list[MapPoint]:
    """The points named in ``text`` (comma-separated; None: all)."""
    if text is None:
        return list(POINTS)
    known = {p.name: p for p in POINTS}
    names = [n.strip() for n in text.split(",") if n.strip()]
    bad = [n for n in names if n not in known]
    if bad or not names:
        raise StudyError(f"--points = {text!r} is not allowed: names among "
                         f"{', '.join(known)}")
    return [known[n] for n in names]


def run(args: argparse.Namespace) -> int:
    """Map the mapped points' demands to their discharge, run the map's points (or read
    them from ``--out``) and write its tables."""
    from arzsumo.scenario import load_scenario, scenario_from_dict

    path = args.scenario or shipped_scenario(FORMER_DEFAULT)
    points = selected_points(args.points)
    sc = load_scenario(path)
    opts = PremiseOptions(args.window, args.pulse_s)
    if args.list:
        runs = map_runs(path, points, args.seeds, sc.run.warmup, opts,
                        pulses=not args.no_pulse)
        mapping = discharge_runs(path, points, sc.run.warmup)
        return print_list([r.run_id for r in mapping + runs])
    with resumable_dir(args.out, f"study-{NAME}") as out:
        discharges, shortfalls, mapped_text = _map_demands(args, path, points,
                                                           sc.run.warmup, out)
        points = mapped_points([p for p in points if not p.mapped or p.name in discharges],
                               discharges, shortfalls)
        runs = map_runs(path, points, args.seeds, sc.run.warmup, opts,
                        pulses=not args.no_pulse)
        rows = ungrouped(run_design(grouped(runs), _task, out, workers=args.workers,
                                    scheduler=args.scheduler, progress=not args.quiet,
                                    label=NAME))
        scenarios = {}
        for r in runs:
            scenarios.setdefault(r.columns["point"], scenario_from_dict(r.scenario, r.source))
        long, wide = map_tables(rows, points, sc.params.length,
                                model_speeds(sc).round_trip, scenarios=scenarios)
        wide["discharge_veh_h"] = [discharges.get(n, math.nan) * VEH_H_PER_VEH_S
                                   for n in wide["point"]] if len(wide) else []
        files = write_map(out, long, wide, MAP_GATES, plots=plots_wanted(args),
                          fields=first_fields(rows))
        if args.docs is not None:
            publish(args.docs, args.page, NAME, "The premise map",
                    _page_body(args.page, wide, mapped_text), files)
    print(map_markdown(wide))
    print(theory_markdown(wide))
    return 0


def _map_demands(args: argparse.Namespace, path: Path, points: Sequence[MapPoint],
                 warmup: float, out: Path
                 ) -> tuple[dict[str, float], dict[str, float], str]:
    """The mapped points' two discharge runs: (point -> q(L), veh/s, for the points
    whose merge did not gridlock; point -> the fill's shortfall, veh/s; the mapping's
    lines)."""
    mapping = discharge_runs(path, points, warmup)
    if not mapping:
        return {}, {}, ""
    kw = {"workers": args.workers, "scheduler": args.scheduler, "progress": not args.quiet}
    found = _labelled(mapping, run_design(mapping, discharge_task, out,
                                          label=f"{NAME} discharge", **kw))
    again = discharge_runs(path, points, warmup, flowing(found))
    second = _labelled(again, run_design(again, discharge_task, out,
                                         label=f"{NAME} discharge at the mapped demand",
                                         **kw))
    text = mapping_lines(found, second)
    print(text)
    return flowing(second), {r["point"]: float(r.get("fill_shortfall_veh_s", 0.0))
                             for r in second}, text


def first_fields(rows: Sequence[Mapping[str, Any]]
                 ) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per point its first seed's baseline HV speed field: (t after the warm-up, s;
    cell centres, m; speeds, km/h), for the figure."""
    out: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    for r in sorted((r for r in rows if r["kind"] == "baseline"), key=lambda r: r["seed"]):
        if r["point"] not in out:
            out[r["point"]] = (np.array(r["t_s"], float) - float(r["t0_s"]),
                               np.array(r["x_m"], float),
                               ms_to_kmh(np.array(r["v_hv"], float)))
    return out


def _labelled(runs: Sequence[StudyRun], rows: Sequence[Mapping[str, Any]]
              ) -> list[dict[str, Any]]:
    """The rows of ``runs`` (in their order) under their runs' point names: a point
    that shares its base point's discharge runs reads their rows as its own."""
    return [{**r, "point": run.columns["point"]} for run, r in zip(runs, rows, strict=True)]


def _page_body(page: str, wide: pd.DataFrame, mapped_text: str) -> str:
    """The results page's generated block: the gates' table, theory beside
    measurement, and the mapping's discharge readings."""
    mapping = (f"\n\nThe mapping's discharge runs (seed {MAPPING_SEED}):\n\n"
               + "\n".join(f"- {line}" for line in mapped_text.splitlines())
               if mapped_text else "")
    return ("Share of seeds on which each premise gate passed, per point of the map, and "
            f"the measured means (`arzsumo study {NAME}`). Tables: "
            f"[premise_map_points.csv]({page}/premise_map_points.csv), "
            f"[premise_map.csv]({page}/premise_map.csv).\n\n{map_markdown(wide)}\n\n"
            "Theory beside measurement: the measured amplification per class (upstream "
            "over downstream amplitude) and the linear string-stability prediction at the "
            "measured operating point (largest gain per vehicle, growth over the class's "
            f"own vehicles on the section; none for Krauss).\n\n{theory_markdown(wide)}"
            + mapping)


def _task(run: StudyRun) -> dict[str, Any]:
    """A point's runs on one seed (one warm-up), the point kept in their rows."""
    rows = run_premise_group(run)["rows"]
    return {"rows": [{"point": run.columns["point"], **r} for r in rows]}


def map_markdown(wide: pd.DataFrame) -> str:
    """The per-point table: pass shares of the gates and the measured means."""
    cols = ["point", "changes", *[f"{g}_passed" for g in MAP_GATES], "v_hv_kmh", "v_av_kmh",
            "rho_hv_veh_km", "rho_av_veh_km", "q_out_veh_h"]
    table = wide[[c for c in cols if c in wide]].rename(
        columns={f"{g}_passed": g for g in MAP_GATES})
    return markdown_table(table, ".3g")


def theory_markdown(wide: pd.DataFrame) -> str:
    """The per-point table of theory beside measurement: the measured amplification and
    wave speed per class, the predicted gain and growth, the operating point and, for a
    mapped point, its measured discharge."""
    cols = ["point", "amplification[hv]_value", "gain_hv", "growth_hv",
            "amplification[av]_value", "gain_av", "growth_av", "waves[hv]_value",
            "queue_tail_m", "v_hv_kmh", "rho_hv_veh_km", "rho_av_veh_km", "q_out_veh_h",
            "discharge_veh_h"]
    table = wide[[c for c in cols if c in wide]].copy()
    if "waves[hv]_value" in table:
        table["waves[hv]_value"] = ms_to_kmh(table["waves[hv]_value"])
    return markdown_table(table.rename(columns={
        "amplification[hv]_value": "ampl hv", "amplification[av]_value": "ampl av",
        "gain_hv": "max|G| hv", "growth_hv": "growth hv", "gain_av": "max|G| av",
        "growth_av": "growth av", "waves[hv]_value": "wave hv km/h"}), ".3g")
