"""What SUMO's options cost and what they change: the open loop of the default scenario,
one option changed at a time (``arzsumo study sumo-options``).

Each variant is the default scenario with one ``[sumo]`` key changed (:data:`VARIANTS`):

* the lateral resolution (0.5 m as shipped: 13 sublanes of the 6.5 m lane; 0.65 m and
  1.3 m, also divisors of the lane width, as SUMO advises);
* the HVs' action step (every 0.1 s step as shipped; 0.5 s);
* the approach length (2500 m as shipped; 1500 and 1000 m: less road upstream of
  x = 0; a queue that reaches the approach's start waits off the network, in SUMO's
  insertion backlog, where it costs nothing per step and its depart delay is charged
  to the whole demand all the same);
* SUMO's eager insertion (every waiting vehicle of the virtual queues tried every step
  as shipped; off: only each edge's first);
* the approach cut into edges of 250 m (one 2500 m edge as shipped): the same road, where
  SUMO's sublane step, quadratic in the vehicles of a lane, costs less.

Every run is an ``arzsumo run`` of the open loop through the sweep engine (its drain
included unless ``--no-drain``), on the same seeds for every variant; ``--vary`` picks
the options (all by default), and the shipped scenario runs once per seed as the
baseline. For each variant against the shipped one, seed by seed, ``sumo_options.csv``
gives the wall and CPU time per run and their ratios, and the paired difference of each
measure (:data:`MEASURES`) with its 95 % t interval and whether it moves beyond seed noise
(the interval excludes zero). The stream's signature (coupling, wave speed and growth, band
powers, the section's density and speed, the whole-demand time per vehicle, teleports and
deadlocks) has margins stated before any run (:data:`MARGINS`): a lever leaves the stream
where it was only when the interval of every signature measure lies inside its margin;
an interval that merely contains zero is not enough. A default may change only then.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.evaluation.stats import paired_difference
from arzsumo.outdir import resumable_dir
from arzsumo.sweep.spec import SweepSpec
from arzsumo.units import S_PER_H
from arzsumo_studies import checks
from arzsumo_studies.common import (
    EXIT_SOME_FAILED,
    RESULTS_DIR,
    StudyError,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.outputs.pages import publish, write_csv

NAME = "sumo-options"
PAGE = "sumo_options"
#: the column naming which variant a run is
OPTION = "option"
#: the variants of each option (field -> values; the shipped value is the baseline)
VARIANTS: dict[str, list[Any]] = {
    "sumo.lateral_resolution_m": [0.65, 1.3, 3.25],
    "sumo.hv_action_step_s": [0.5],
    "sumo.approach_length_m": [1500.0, 1000.0],
    "sumo.eager_insert": [False],
    "sumo.approach_piece_m": [250.0],
    "sumo.step_length_s": [0.2],
}
#: summary column -> (label, unit factor from SI, unit)
MEASURES: dict[str, tuple[str, float, str]] = {
    "network.time_spent_s.total": ("window time spent", 1 / S_PER_H, "veh h"),
    "network_whole_demand.time_spent_s.total": ("whole-demand time spent", 1 / S_PER_H, "veh h"),
    "network_whole_demand.time_loss_s.total": ("whole-demand time loss", 1 / S_PER_H, "veh h"),
    "network_whole_demand.depart_delay_s.total": ("whole-demand depart delay", 1 / S_PER_H,
                                                  "veh h"),
    "network_whole_demand.ramp_wait_s.p95": ("ramp wait p95", 1.0, "s"),
    "section.speed_mean_kmh.h": ("HV mean speed", 1.0, "km/h"),
    "section.speed_mean_kmh.a": ("AV mean speed", 1.0, "km/h"),
    "section.waves.h.oscillation_kmh": ("HV oscillation", 1.0, "km/h"),
    "section.waves.a.oscillation_kmh": ("AV oscillation", 1.0, "km/h"),
    "section.waves.h.band_power_kmh2": ("HV band power", 1.0, "(km/h)^2"),
    "section.speed_wave.h.speed_kmh": ("HV wave speed", 1.0, "km/h"),
    "section.inlet.rho_h_veh_km": ("inlet HV density", 1.0, "veh/km"),
    "section.inlet.v_h_kmh": ("inlet HV speed", 1.0, "km/h"),
    "rmse_blocks.replay.rho_h.relative": ("HV replay error", 100.0, "%"),
    "rmse_blocks.replay.rho_a.relative": ("AV replay error", 100.0, "%"),
    "whole_demand_time_per_vehicle_s": ("whole-demand time per vehicle", 1.0, "s"),
    "section.waves.a.band_power_kmh2": ("AV band power", 1.0, "(km/h)^2"),
    "section.waves.h.growth_per_km": ("HV wave growth", 1.0, "1/km"),
    "section_trend.mean_veh": ("section's mean vehicles", 1.0, "veh"),
    "hv_file_gap_kmh": ("HV files' speed gap", 1.0, "km/h"),
    "teleports": ("teleports", 1.0, "veh"),
    "deadlocked": ("deadlocks", 1.0, "runs"),
}
#: the signature's margins, stated before the runs: a measure stays where it was when its
#: paired 95 % interval lies inside +-margin ("rel": that share of the shipped mean; "abs":
#: in the measure's unit). 10 % where the issue of a lever is the level of a quantity; 2
#: km/h on the wave speed; growth rates and the files' gap near 0 take absolute margins
#: (0.2 per km: a fifth of the IDM stream's 0.8; 2 km/h between files); none of a
#: deadlock or a teleport may appear.
MARGINS: dict[str, tuple[str, float]] = {
    "whole_demand_time_per_vehicle_s": ("rel", 0.10),
    "section.speed_mean_kmh.h": ("rel", 0.10),
    "section.speed_mean_kmh.a": ("rel", 0.10),
    "section_trend.mean_veh": ("rel", 0.10),
    "section.waves.h.band_power_kmh2": ("rel", 0.10),
    "section.waves.a.band_power_kmh2": ("rel", 0.10),
    "section.speed_wave.h.speed_kmh": ("abs", 2.0),
    "section.waves.h.growth_per_km": ("abs", 0.2),
    "hv_file_gap_kmh": ("abs", 2.0),
    "teleports": ("abs", 0.0),
    "deadlocked": ("abs", 0.0),
}
WALL, CPU = "execution.wall_s", "execution.cpu_s"


def with_signature(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` (a sweep's table) with the signature's derived columns: the whole-demand time
    per vehicle of the demand (s), the spread of the HV files' mean speeds (km/h; 0 with one
    file: the coupling) and whether the run deadlocked (0/1)."""
    out = df.copy()
    tts, n = ("network_whole_demand.time_spent_s.total",
              "network_whole_demand.vehicles.loaded.total")
    if tts in out and n in out:
        out["whole_demand_time_per_vehicle_s"] = out[tts] / out[n]
    files = [c for c in out if c.startswith("section.waves.h.files.")
             and c.endswith(".speed_mean_kmh")]
    if files:
        speeds = out[files].to_numpy(float)
        gap = np.nanmax(speeds, axis=1) - np.nanmin(speeds, axis=1)
        out["hv_file_gap_kmh"] = np.where(np.isfinite(gap), gap, 0.0)
    grid = "network_whole_demand.drain.gridlock"
    if grid in out:
        out["deadlocked"] = out[grid].fillna(False).astype(float)
    return out


def inside_margin(low: float, high: float, margin: float) -> bool:
    """Whether the interval [low, high] lies inside [-margin, +margin]."""
    return -margin <= low and high <= margin


def shipped_values(scenario: str = "default.toml") -> dict[str, Any]:
    """The value of every option of :data:`VARIANTS` in the shipped ``scenario`` (field ->
    value in the file's units; SUMO's default where the file does not set the key). The
    four options' file units are SI, so the parsed configuration gives them as they are."""
    from arzsumo.scenario import load_scenario
    from arzsumo.scenario.sumo import SUMO_KEYS

    cfg = load_scenario(shipped_scenario(scenario)).sumo
    return {f: getattr(cfg, SUMO_KEYS[f.split(".", 1)[1]].field) for f in VARIANTS}


def options_spec(seeds: list[int], scenario: str = "default.toml", drain: bool = True,
                 vary: tuple[str, ...] = ()):
    """The sweep of the study: one axis per option of ``vary`` (keys of ``[sumo]``; empty:
    every option of :data:`VARIANTS`), varied one at a time, the first axis led by its
    shipped value (the baseline); without ``drain`` the runs end with the control window
    (the whole-demand measures then stop there too, and are left out)."""
    chosen = variants_of(vary)
    shipped = shipped_values(scenario)
    axes = [{"field": f, "values": ([shipped[f]] if i == 0 else []) + values,
             "group": OPTION} for i, (f, values) in enumerate(chosen.items())]
    fixed: dict[str, Any] = {"run.controller": "open"}
    if not drain:
        fixed["sumo.drain_max_s"] = 0.0
    return study_spec(NAME, shipped_scenario(scenario), seeds=list(seeds), set=fixed,
                      axis=axes)


def variants_of(vary: tuple[str, ...]) -> dict[str, list[Any]]:
    """The variants ``vary`` picks (field -> values), in ``vary``'s order: an entry ``KEY``
    takes every value of that ``[sumo]`` key in :data:`VARIANTS`, ``KEY=VALUE`` the one
    value so named (as the tables name it); empty: every variant. Unknown entries are left
    out (the options check them)."""
    if not vary:
        return {f: list(v) for f, v in VARIANTS.items()}
    picked: dict[str, list[Any]] = {}
    for entry in vary:
        key = entry.split("=", 1)[0]
        field = f"sumo.{key}"
        named = [v for v in VARIANTS.get(field, [])
                 if entry == key or variant_name(key, v) == entry]
        picked.setdefault(field, []).extend(v for v in named if v not in picked[field])
    return {f: v for f, v in picked.items() if v}


def variant_names() -> list[str]:
    """Every variant of :data:`VARIANTS` by its name, ``KEY=VALUE``."""
    return [variant_name(f.split(".", 1)[1], v) for f, vs in VARIANTS.items() for v in vs]


def variant_name(key: str, value: Any) -> str:
    """``key=value`` as the study's tables name a variant."""
    text = str(value).lower() if isinstance(value, bool | np.bool_) else f"{value:g}"
    return f"{key}={text}"


def variant_of(row: pd.Series) -> str:
    """The variant a run of the sweep is: the option its group column names, its value."""
    return variant_name(row[OPTION], row[row[OPTION]])


def compare(df: pd.DataFrame, drained: bool = True, base_name: str | None = None
            ) -> pd.DataFrame:
    """One row per variant and measure: the paired difference against the shipped options
    ``base_name`` (a :func:`variant_name`; None: the variant of the sweep's first run, the
    shipped value of its first axis) over the seeds both finished (module docstring);
    whole-demand measures only when the runs were ``drained``."""
    ok = with_signature(df[df["status"] == "ok"])
    ok["variant"] = ok.apply(variant_of, axis=1)
    base_name = base_name or variant_of(df.iloc[0])
    base = ok[ok["variant"] == base_name].set_index("seed")
    rows = []
    for variant, runs in ok.groupby("variant", sort=False):
        runs = runs.set_index("seed")
        seeds = sorted(set(runs.index) & set(base.index))
        cost = _cost(runs.loc[seeds], base.loc[seeds])
        for col, (label, factor, unit) in MEASURES.items():
            if col not in runs or (not drained and col.startswith("network_whole_demand")):
                continue
            a = runs.loc[seeds, col].to_numpy(float) * factor
            b = base.loc[seeds, col].to_numpy(float) * factor
            same = variant == base_name
            pc = None if same or len(seeds) < 2 else _paired(a, b)
            low, high = (pc.t.low, pc.t.high) if pc else (0.0, 0.0)
            margin = _margin(col, float(np.nanmean(b)))
            rows.append({
                "variant": variant, "seeds": len(seeds), **cost, "measure": label,
                "unit": unit, "base_mean": float(np.nanmean(b)),
                "variant_mean": float(np.nanmean(a)),
                "diff_mean": pc.mean_diff if pc else 0.0, "diff_low": low, "diff_high": high,
                "moves": bool(pc and not pc.t.covers(0.0)), "margin": margin,
                "inside": (None if np.isnan(margin) or same
                           else inside_margin(low, high, margin))})
    return pd.DataFrame(rows)


def _paired(a: np.ndarray, b: np.ndarray):
    """The paired difference a - b, or, when it is 0 on every seed (a count that never
    happens), an exact zero interval (a t interval of no spread is undefined)."""
    d = a - b
    if np.all(d[np.isfinite(d)] == 0.0):
        zero = SimpleNamespace(low=0.0, high=0.0, covers=lambda v: v == 0.0)
        return SimpleNamespace(mean_diff=0.0, t=zero)
    return paired_difference(a, b, n_resamples=999)


def _margin(col: str, base_mean: float) -> float:
    """The margin of :data:`MARGINS` for ``col`` in its unit (NaN: not a signature
    measure)."""
    if col not in MARGINS:
        return float("nan")
    kind, value = MARGINS[col]
    return value * abs(base_mean) if kind == "rel" else value


def _cost(runs: pd.DataFrame, base: pd.DataFrame) -> dict[str, float]:
    """Wall and CPU time per run (s) and their mean ratios to the baseline's, seed by
    seed (CPU NaN for runs that did not record it)."""
    out = {}
    for name, col in (("wall", WALL), ("cpu", CPU)):
        if col not in runs or col not in base:
            out |= {f"{name}_s_per_run": float("nan"), f"{name}_ratio": float("nan")}
            continue
        mine, theirs = runs[col].to_numpy(float), base[col].to_numpy(float)
        out |= {f"{name}_s_per_run": float(np.mean(mine)),
                f"{name}_ratio": float(np.mean(mine / theirs))}
    return out


def markdown(table: pd.DataFrame) -> str:
    """The comparison as a Markdown table, one line per variant."""
    lines = ["| variant | seeds | wall s / run | wall ratio | CPU ratio | "
             + " | ".join(f"{m} ({u})" for m, u in dict.fromkeys(
                 zip(table["measure"], table["unit"], strict=True)))
             + " |", "|---|---:|---:|---:|---:|" + "---|" * table["measure"].nunique()]
    for variant, rows in table.groupby("variant", sort=False):
        cells = []
        for r in rows.itertuples():
            if r.diff_low == r.diff_high == 0.0:
                cells.append(f"{r.base_mean:.3g}")
            else:
                star = " **moves**" if r.moves else ""
                if r.inside is not None and not pd.isna(r.inside):
                    star += (f" inside +-{r.margin:.3g}" if r.inside
                             else f" **outside +-{r.margin:.3g}**")
                cells.append(f"{r.diff_mean:+.3g} [{r.diff_low:+.3g}, {r.diff_high:+.3g}]"
                             f"{star}")
        r0 = rows.iloc[0]
        lines.append(f"| {variant} | {r0.seeds} | {r0.wall_s_per_run:.0f} | "
                     f"{r0.wall_ratio:.2f} | {r0.cpu_ratio:.2f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def signature_markdown(table: pd.DataFrame) -> str:
    """Per variant, its signature (the measures with a margin, :data:`MARGINS`) as rows:
    the shipped mean, the paired difference and whether it lies inside the margin; the
    heading says whether the stream kept its signature (every interval inside)."""
    blocks = []
    sig = table[table["margin"].notna() & table["inside"].notna()]
    for variant, rows in sig.groupby("variant", sort=False):
        moved = [r.measure for r in rows.itertuples() if not r.inside]
        r0 = rows.iloc[0]
        verdict = ("kept: every interval inside its margin" if not moved
                   else "moved: " + ", ".join(moved) + " outside")
        lines = [f"**{variant}** ({r0.seeds} paired seeds, CPU ratio {r0.cpu_ratio:.2f}, "
                 f"wall ratio {r0.wall_ratio:.2f}): the signature is {verdict}.", "",
                 "| measure | unit | shipped mean | variant minus shipped [95 % t] | margin "
                 "| inside |", "|---|---|---:|---|---:|---|"]
        lines += [f"| {r.measure} | {r.unit} | {r.base_mean:.4g} | {r.diff_mean:+.3g} "
                  f"[{r.diff_low:+.3g}, {r.diff_high:+.3g}] | +-{r.margin:.3g} | "
                  f"{'yes' if r.inside else '**no**'} |" for r in rows.itertuples()]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks)


@dataclass(frozen=True)
class SumoOptionsOptions(checks.Shared):
    """What the study runs and where it writes.

    Parameters
    ----------
    seeds : tuple of int
        SUMO seeds, the same for every variant.
    drain : bool
        Run each run's drain after the control window (False: end with the window;
        faster, no whole-demand measures).
    vary : tuple of str
        The ``[sumo]`` keys varied (keys of :data:`VARIANTS`; empty: all), or one value
        of a key as ``KEY=VALUE`` (:func:`variants_of`).

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    seeds: tuple[int, ...] = tuple(range(1, 11))
    drain: bool = True
    vary: tuple[str, ...] = ()
    out: Path = RESULTS_DIR / NAME

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)
        known = [f.split(".", 1)[1] for f in VARIANTS]
        named = variant_names()
        bad = [k for k in self.vary if k not in known and k not in named]
        if bad or len(set(self.vary)) != len(self.vary):
            raise StudyError(f"--vary = {','.join(self.vary)} is not allowed: "
                             f"distinct options of {', '.join(known)}, or one value "
                             f"of one, of {', '.join(named)}")

    def spec(self) -> SweepSpec:
        """The study's sweep (:func:`options_spec`)."""
        return options_spec(list(self.seeds), drain=self.drain, vary=self.vary)


@dataclass(frozen=True)
class SumoOptionsResult:
    """The study's outcome: the exit ``code`` (0; 4 when a run did not end ``ok``), the
    run ``statuses`` (status -> runs), the comparison ``table`` (one row per variant and
    measure), its markdown ``text`` and the ``files`` written."""

    code: int
    statuses: dict[str, int]
    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def design(opts: SumoOptionsOptions) -> list[str]:
    """The run IDs of the study's sweep."""
    return [r.run_id for r in opts.spec().runs()]


def run_sumo_options(opts: SumoOptionsOptions, *, progress: bool = True
                     ) -> SumoOptionsResult:
    """Run the missing variants and seeds, write the comparison.

    ``opts``: the study's :class:`SumoOptionsOptions`; ``progress``: draw a progress bar.

    Returns
    -------
    SumoOptionsResult
        The exit code, the statuses, the comparison and the file written
        (``sumo_options.csv`` in ``opts.out``).
    """
    from arzsumo.sweep.driver import run_sweep

    spec = opts.spec()
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        rep = run_sweep(spec, Path(out) / "sweep", workers=opts.workers,
                        scheduler=opts.scheduler, progress=progress, plots=False)
        first = spec.runs()[0]
        table = compare(rep.table, drained=opts.drain, base_name=variant_name(
            first.columns[OPTION], first.columns[first.columns[OPTION]]))
        files = [write_csv(table, Path(out) / f"{PAGE}.csv")]
        text = markdown(table) + "\n\n" + signature_markdown(table)
        if opts.docs is not None:
            body = ("The open loop of the default scenario, one SUMO option changed at a "
                    f"time, paired by seed (`arzsumo study {NAME}`). Each cell: the "
                    "variant minus the shipped options, mean [95 % t interval]; **moves**: "
                    "the interval excludes zero. The first row gives the shipped means."
                    + (" The runs end with the control window (`--no-drain`)."
                       if not opts.drain else "") + "\n\n"
                    f"{text}\n\nTable: [{PAGE}.csv]({PAGE}/{PAGE}.csv).")
            publish(opts.docs, PAGE, NAME, "What SUMO's options cost and change", body,
                    [(p, p.name) for p in files])
    bad = sum(v for k, v in rep.statuses.items() if k != "ok")
    return SumoOptionsResult(EXIT_SOME_FAILED if bad else 0, dict(rep.statuses), table,
                             text, tuple(files))
