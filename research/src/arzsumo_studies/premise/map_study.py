"""Where the paper's premise holds in SUMO: the premise gates over what the mission leaves
free on the SUMO side (``arzsumo study premise-map``).

The frame stays fixed (1 km, one 6.5 m lane under the sublane model, HV and AV types,
the ramp meter at the outlet). Each :class:`MapPoint` changes a few ``[sumo]`` keys of
the base scenario: the lateral behaviour, the HVs' car following, the downstream
bottleneck, the AV share and the demand (:data:`POINTS`). The car-following points
are first mapped to their own discharge (two discharge runs on a seed no gate reads:
:mod:`arzsumo_studies.premise.map_points`); a point that gridlocks there is left out.
Per point and seed an
open-loop baseline (:mod:`arzsumo_studies.premise.runs`), and on the point's first seed
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

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.units import VEH_H_PER_VEH_S
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    StudyError,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.design import StudyRun, design_runs, run_design
from arzsumo_studies.outputs.pages import publish
from arzsumo_studies.outputs.premise_map import write_map
from arzsumo_studies.premise.map_points import (
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
from arzsumo_studies.premise.map_tables import (
    MAP_GATES,
    first_fields,
    map_markdown,
    map_tables,
    theory_markdown,
)
from arzsumo_studies.premise.runs import (
    PremiseOptions,
    grouped,
    horizon_periods,
    run_premise_group,
    ungrouped,
)
from arzsumo_studies.premise.study import (
    model_speeds,
)

#: the results page this study keeps a block of
PAGE = "premise_map"
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


# -- the command ---------------------------------------------------------------------------
def selected_points(names: str | Sequence[str] | None) -> list[MapPoint]:
    """The points named in ``names`` (a sequence, or comma-separated; None: all)."""
    if names is None:
        return list(POINTS)
    known = {p.name: p for p in POINTS}
    text = names if isinstance(names, str) else ",".join(names)
    wanted = [n.strip() for n in text.split(",") if n.strip()]
    bad = [n for n in wanted if n not in known]
    if bad or not wanted:
        raise StudyError(f"--points = {text!r} is not allowed: names among "
                         f"{', '.join(known)}")
    return [known[n] for n in wanted]


@dataclass(frozen=True)
class MapOptions(checks.Shared):
    """What a premise map runs and where it writes (SI: s).

    ``scenario``: the base scenario file every point changes (None: the former default);
    ``points``: point names (None: all of :data:`POINTS`); ``seeds``: the gate seeds (the
    first also pulsed when ``pulses``); ``window_s``, ``pulse_s``: the baseline and pulse
    window and the pulse's hold; ``out``: the study's directory (resumable); ``docs``,
    ``page``: the results page to regenerate (None: none); ``plots``; ``workers``,
    ``scheduler``, ``progress``: how the runs are run.
    """

    scenario: Path | None = None
    points: tuple[str, ...] | None = None
    seeds: tuple[int, ...] = (1, 2)
    window_s: float = 540.0
    pulse_s: float = 25.0
    pulses: bool = True
    out: Path = RESULTS_DIR / NAME
    page: str = PAGE
    plots: bool = True
    progress: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.seeds:
            raise StudyError("seeds = () is not allowed: at least one seed")


@dataclass(frozen=True)
class MapResult:
    """A map's outcome: the ``points`` as run (their demands mapped), the measured
    ``discharges`` (point -> q(L), veh/s), the per point, seed and gate table ``long``,
    the per-point table ``wide``, the mapping's lines and the ``files`` written."""

    points: tuple[MapPoint, ...]
    discharges: Mapping[str, float]
    long: pd.DataFrame
    wide: pd.DataFrame
    mapping: str
    files: tuple[Path, ...]


def design(opts: MapOptions) -> list[str]:
    """The run IDs a map would run: the discharge runs, then the gates' runs."""
    from arzsumo.scenario import load_scenario

    path = opts.scenario or shipped_scenario(FORMER_DEFAULT)
    points = selected_points(opts.points)
    warmup = load_scenario(path).run.warmup
    runs = map_runs(path, points, opts.seeds, warmup, PremiseOptions(opts.window_s,
                                                                     opts.pulse_s),
                    pulses=opts.pulses)
    return [r.run_id for r in discharge_runs(path, points, warmup) + runs]


def run_map(opts: MapOptions) -> MapResult:
    """Map the mapped points' demands to their discharge, run the map's points (or read
    them from ``opts.out``) and write its tables and figures."""
    from arzsumo.scenario import load_scenario, scenario_from_dict

    path = opts.scenario or shipped_scenario(FORMER_DEFAULT)
    points = selected_points(opts.points)
    sc = load_scenario(path)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        discharges, shortfalls, mapped_text = _map_demands(opts, path, points,
                                                           sc.run.warmup, out)
        points = mapped_points([p for p in points if not p.mapped or p.name in discharges],
                               discharges, shortfalls)
        runs = map_runs(path, points, opts.seeds, sc.run.warmup,
                        PremiseOptions(opts.window_s, opts.pulse_s), pulses=opts.pulses)
        rows = ungrouped(run_design(grouped(runs), _task, out, workers=opts.workers,
                                    scheduler=opts.scheduler, progress=opts.progress,
                                    label=NAME))
        scenarios = {}
        for r in runs:
            scenarios.setdefault(r.columns["point"], scenario_from_dict(r.scenario, r.source))
        long, wide = map_tables(rows, points, sc.params.length,
                                model_speeds(sc).round_trip, scenarios=scenarios)
        wide["discharge_veh_h"] = [discharges.get(n, math.nan) * VEH_H_PER_VEH_S
                                   for n in wide["point"]] if len(wide) else []
        files = write_map(out, long, wide, MAP_GATES, plots=opts.plots,
                          fields=first_fields(rows))
        if opts.docs is not None:
            publish(opts.docs, opts.page, NAME, "The premise map",
                    _page_body(opts.page, wide, mapped_text), files)
    return MapResult(tuple(points), discharges, long, wide, mapped_text,
                     tuple(Path(f) for f in files))


def _map_demands(opts: MapOptions, path: Path, points: Sequence[MapPoint],
                 warmup: float, out: Path
                 ) -> tuple[dict[str, float], dict[str, float], str]:
    """:func:`map_demands` with the map's options."""
    return map_demands(path, points, warmup, out, workers=opts.workers,
                       scheduler=opts.scheduler, progress=opts.progress)


def map_demands(path: Path, points: Sequence[MapPoint], warmup: float, out: Path, *,
                workers: int | None = None, scheduler: str | None = None,
                progress: bool = True, label: str = NAME
                ) -> tuple[dict[str, float], dict[str, float], str]:
    """The mapped points' two discharge runs on the scenario at ``path`` (kept in
    ``out``): (point -> q(L), veh/s, for the points whose merge did not gridlock; point
    -> the fill's shortfall, veh/s; the mapping's lines)."""
    mapping = discharge_runs(path, points, warmup)
    if not mapping:
        return {}, {}, ""
    kw = {"workers": workers, "scheduler": scheduler, "progress": progress}
    found = _labelled(mapping, run_design(mapping, discharge_task, out,
                                          label=f"{label} discharge", **kw))
    again = discharge_runs(path, points, warmup, flowing(found))
    second = _labelled(again, run_design(again, discharge_task, out,
                                         label=f"{label} discharge at the mapped demand",
                                         **kw))
    text = mapping_lines(found, second)
    print(text)
    return flowing(second), {r["point"]: float(r.get("fill_shortfall_veh_s", 0.0))
                             for r in second}, text


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
