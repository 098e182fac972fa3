"""The evaluation of controllers over seeds: per measure, mean with its CI per controller
and the paired difference against a baseline (the open loop) over the same seeds.

Pure: reads a table with one row per run (``controller``, ``seed`` and the measures as
dotted summary keys in SI, as the sweep table has them); values come out in the human
units of :data:`MEASURES`. The table and its intervals: docs/outputs.md, "``arzsumo
evaluate``"; :mod:`arzsumo.outputs.evaluation` writes them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from arzsumo.evaluation.stats import StatisticsError, mean_ci, paired_difference
from arzsumo.units import S_PER_H


@dataclass(frozen=True)
class Measure:
    """One measure of the evaluation.

    ``key``: dotted summary key (SI); ``scale``: factor from the summary's unit to
    ``unit``; ``lower_is_better``: direction used for wins and losses; ``aliases``:
    former names of the key, read where a run (an older summary) lacks ``key``.
    """

    key: str
    label: str
    unit: str
    scale: float = 1.0
    lower_is_better: bool = True
    aliases: tuple[str, ...] = ()


def _split(key: str, label: str, unit: str, scale: float,
           parts: tuple[str, ...] = ("mainline", "ramp", "total")) -> tuple[Measure, ...]:
    return tuple(Measure(f"{key}.{part}", f"{label}, {part}", unit, scale) for part in parts)


_CLASSES = (("h", "HV"), ("a", "AV"))
_VEH_H = 1 / S_PER_H

_WHOLE = "network_whole_demand"
_WAIT = f"{_WHOLE}.ramp_wait_s"

#: the measures, in report order: the whole demand first (every loaded vehicle to its
#: arrival: what a controller leaves behind is charged), then the waves, then the meter's
#: counts, then the control window's own measures
MEASURES: tuple[Measure, ...] = (
    *_split(f"{_WHOLE}.time_spent_s", "whole-demand time spent", "veh h", _VEH_H,
            ("total", "mainline", "ramp")),
    Measure(f"{_WHOLE}.time_loss_s.total", "whole-demand time loss, total", "veh h", _VEH_H),
    Measure(f"{_WHOLE}.fuel_g.total", "whole-demand fuel", "kg", 1e-3),
    Measure(f"{_WAIT}.p95", "ramp wait at the meter, 95th percentile", "s"),
    Measure(f"{_WAIT}.max", "ramp wait at the meter, maximum", "s"),
    Measure(f"{_WAIT}.over_limit", "ramp vehicles waiting over 240 s", "veh"),
    Measure(f"{_WHOLE}.drain.duration_s", "drain after the window", "s"),
    *(Measure(f"section.speed_oscillation_kmh.{c}", f"section speed oscillation, {name}",
              "km/h") for c, name in _CLASSES),
    *(Measure(f"section.waves.{c}.band_power_kmh2",
              f"section stop-and-go band power (1-10 min), {name}", "(km/h)^2")
      for c, name in _CLASSES),
    *(Measure(f"section.waves.{c}.short_power_kmh2",
              f"section short-wave power (20 s-1 min), {name}", "(km/h)^2")
      for c, name in _CLASSES),
    *(Measure(f"section.waves.{c}.growth_per_km", f"section wave growth upstream, {name}",
              "1/km") for c, name in _CLASSES),
    Measure("plan_changes", "meter plan changes", "count"),
    Measure("light_changes", "ramp-light changes", "count"),
    Measure("triggers", "controller updates (triggers)", "count"),
    Measure("meter.override_s", "queue override on (window)", "s"),
    *_split("network.time_spent_s", "window time spent", "veh h", _VEH_H),
    *_split("network.time_loss_s", "window time loss", "veh h", _VEH_H),
    *_split("network.depart_delay_s", "window depart delay", "veh h", _VEH_H),
    Measure("network.throughput_veh_h.section_outlet", "throughput, section outlet", "veh/h",
            1.0, lower_is_better=False),
    Measure("network.throughput_veh_h.network_exit", "throughput, network exit", "veh/h",
            1.0, lower_is_better=False),
    Measure("network.fuel_g.total", "window fuel", "kg", 1e-3),
    Measure("network.co2_g.total", "window CO2", "kg", 1e-3),
    *(Measure(f"section.speed_spread_kmh.{c}",
              f"section speed spread across vehicles, {name}", "km/h",
              aliases=(f"section.speed_sd_kmh.{c}",)) for c, name in _CLASSES),
    Measure("section.TTT.total", "section TTT", "veh h", _VEH_H),
    Measure("section.total_delay.total", "section delay", "veh h", _VEH_H),
)

#: columns of the long table, in order (``evaluation.csv``)
COLUMNS = ("measure", "label", "unit", "lower_is_better", "controller", "n", "mean",
           "ci_low", "ci_high", "diff_mean", "diff_ci_low", "diff_ci_high",
           "diff_boot_low", "diff_boot_high", "wins", "losses", "ties")


def per_seed(runs: pd.DataFrame, measure: Measure, controllers: Sequence[str]) -> pd.DataFrame:
    """Seeds x controllers table of ``measure`` in its human unit (NaN where missing)."""
    values = pd.Series(math.nan, index=runs.index)
    for key in (measure.key, *measure.aliases):     # a former name fills older runs
        if key in runs:
            numbers = pd.to_numeric(runs[key].astype(object), errors="coerce")
            values = values.fillna(pd.Series(numbers, index=runs.index, dtype=float))
    values = values * measure.scale
    if measure.key.startswith(f"{_WHOLE}.") and f"{_WHOLE}.complete" in runs:
        # a run whose drain did not empty the network (a gridlock, the drain limit) has
        # not charged every vehicle: it has no whole-demand value
        complete = runs[f"{_WHOLE}.complete"].astype(str).str.lower() == "true"
        values = values.where(complete)
    wide = pd.DataFrame({"seed": runs["seed"], "controller": runs["controller"],
                         "value": values}).pivot(index="seed", columns="controller",
                                                 values="value")
    return wide.reindex(columns=list(controllers)).sort_index()


def _row(measure: Measure, controller: str, values: np.ndarray,
         base: np.ndarray) -> dict[str, object]:
    row: dict[str, object] = {"measure": measure.key, "label": measure.label,
                              "unit": measure.unit, "lower_is_better": measure.lower_is_better,
                              "controller": controller}
    row.update(dict.fromkeys(COLUMNS[5:], math.nan))
    row.update(n=0, wins=0, losses=0, ties=0)
    try:
        m = mean_ci(values)
    except StatisticsError:          # no value for this controller
        return row
    row.update(n=m.n, mean=m.mean, ci_low=m.low, ci_high=m.high)
    try:
        d = paired_difference(values, base, lower_is_better=measure.lower_is_better)
    except StatisticsError:          # no seed with both values
        return row
    row.update(diff_mean=d.mean_diff, diff_ci_low=d.t.low, diff_ci_high=d.t.high,
               diff_boot_low=d.bootstrap.low, diff_boot_high=d.bootstrap.high,
               wins=d.wins, losses=d.losses, ties=d.ties)
    return row


def evaluate(runs: pd.DataFrame, controllers: Sequence[str], baseline: str = "open",
             measures: Sequence[Measure] = MEASURES) -> pd.DataFrame:
    """The long table (:data:`COLUMNS`): one row per measure and controller.

    ``runs``: one row per finished run (``controller``, ``seed`` and the measures' keys,
    SI); ``controllers`` in report order, ``baseline`` among them: every other is compared
    with it seed by seed (its own row has a difference of 0, zero-width interval).
    """
    if baseline not in controllers:
        raise StatisticsError(f"baseline = {baseline!r} is not among the controllers "
                              f"{list(controllers)}; allowed: one of them")
    rows = []
    for measure in measures:
        wide = per_seed(runs, measure, controllers)
        base = wide[baseline].to_numpy(float)
        rows += [_row(measure, c, wide[c].to_numpy(float), base) for c in controllers]
    return pd.DataFrame(rows, columns=list(COLUMNS))


def paired_differences(runs: pd.DataFrame, measure: Measure, controllers: Sequence[str],
                       baseline: str = "open") -> dict[str, np.ndarray]:
    """Per controller (baseline excluded), the per-seed differences against the baseline
    in the measure's human unit, seeds where either value is missing left out."""
    wide = per_seed(runs, measure, controllers)
    diffs = {c: (wide[c] - wide[baseline]).to_numpy(float) for c in controllers if c != baseline}
    return {c: d[np.isfinite(d)] for c, d in diffs.items()}


def _fmt(value: float, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return f"{value:.{digits}g}" if abs(value) < 10 ** digits else f"{value:.0f}"


def markdown(long: pd.DataFrame, baseline: str = "open") -> str:
    """A readable Markdown table of the long table: per measure and controller, the mean
    [95 % CI], the paired difference against ``baseline`` [95 % CI, t] and wins/losses/ties
    over seeds (a win: better than the baseline on that seed)."""
    lines = [f"| measure | unit | controller | n | mean [95 % CI] | minus {baseline} "
             "[95 % CI] | wins / losses / ties |", "|---|---|---|---|---|---|---|"]
    for r in long.itertuples(index=False):
        mean = f"{_fmt(r.mean)} [{_fmt(r.ci_low)}, {_fmt(r.ci_high)}]"
        if r.controller == baseline:
            diff, wlt = "(baseline)", ""
        else:
            diff = f"{_fmt(r.diff_mean)} [{_fmt(r.diff_ci_low)}, {_fmt(r.diff_ci_high)}]"
            wlt = f"{r.wins} / {r.losses} / {r.ties}"
        better = "lower" if r.lower_is_better else "higher"
        lines.append(f"| {r.label} ({better} is better) | {r.unit} | {r.controller} | {r.n} "
                     f"| {mean} | {diff} | {wlt} |")
    return "\n".join(lines)
