"""The premise map's tables (pure: rows in, frames out): the gates per point and seed
from the runs' rows, the per-point measures, the linear theory at each seed's measured
operating point, and the markdown and figure inputs (``arzsumo study premise-map``,
:mod:`arzsumo_studies.premise.map_study`)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.scenario import Scenario
from arzsumo.units import VEH_H_PER_VEH_S, VEH_KM_PER_VEH_M, ms_to_kmh
from arzsumo_studies.gates import GateResult, PremiseThresholds
from arzsumo_studies.gates.instability import round_trip_time
from arzsumo_studies.gates.queue_tail import queue_tail
from arzsumo_studies.outputs.pages import markdown_table
from arzsumo_studies.premise.floors import (
    LATE_SHARE,
    class_fields,
    classes_of,
    deviation_norms,
)
from arzsumo_studies.premise.map_points import COUPLED, MapPoint
from arzsumo_studies.premise.study import (
    operating_gates,
    read_pulse,
    speed_gates,
    theory_at,
)

#: the gates the map decides, in the order of its table and figure
MAP_GATES = ("coupling[hv]", "coupling[av]", "waves[hv]", "waves[av]",
             "amplification[hv]", "amplification[av]", "pulse", "stationary", "inserted",
             "ramp_queue")


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
    stretch from x = 0, :func:`~arzsumo_studies.gates.queue_tail.queue_tail`; the
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
    (:func:`~arzsumo_studies.premise.study.theory_at`), averaged over seeds: per class the
    largest gain per vehicle ``gain_*`` and the growth over the section's vehicles
    ``growth_*`` (NaN for a model without one, e.g. Krauss)."""
    preds = [theory_at(r["baseline"], sc) for r in rows.values()]
    out = {}
    for c in ("hv", "av"):
        for key, attr in (("gain", "gain"), ("growth", "growth")):
            vals = [getattr(p[c], attr) for p in preds if c in p]
            out[f"{key}_{c}"] = float(np.mean(vals)) if vals else math.nan
    return out


def changes_text(keys: Mapping[str, Any]) -> str:
    """A point's changes as ``key = value``, the ``[sumo]`` keys by their names alone and
    the coupled base's values left out."""
    def label(k: str) -> str:
        return k.removeprefix("sumo.")
    return "; ".join(f"{label(k)} = {v}" for k, v in keys.items()
                     if not (k.startswith("sumo.") and COUPLED.get(label(k), object()) == v))


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
                               "changes": changes_text(p.set),
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
