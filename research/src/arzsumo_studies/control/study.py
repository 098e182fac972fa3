"""The paper's controllers in SUMO, two experiments per seed (``arzsumo study control``).

Every controller runs on the same seeds of one scenario (the shipped default unless
``--scenario``), twice, paired against the open loop of its experiment:

- **regulation**: the stationary congested state the warm-up left, over the control
  window, then the drain (the whole demand is charged: docs/whole_demand.md);
- **disturbance**: the same, with the edge past the merge slowed at the start of control
  (:data:`DISTURBANCE`, a ``[disturbance]`` table: the paper's section 5 asks how fast a
  law removes a perturbation). The slowdown is identical on every controller of a seed,
  and up to the start of control every run of a seed is the same run.

Each experiment is an evaluation (:func:`~arzsumo.sweep.evaluate.run_evaluation`, into
``OUT/<experiment>/``; resumable, Dask-capable, one warm-up per seed). To its measures the
study adds the deviation from the stationary state that every run records
(``section.deviation``, :mod:`arzsumo.evaluation.decay`: the decay time and the
integrated deviation norm from SUMO's state over the warm-up's last minutes, the same
for every controller of a seed), the release time and the paper's J_fuel and J_discom
over the section. Tables: per experiment
``OUT/<experiment>/control.{csv,md}`` (every measure: mean with its 95 % interval, the
paired difference against the open loop with Student t and BCa bootstrap intervals,
wins and losses), ``OUT/<experiment>/control.png`` (the per-seed paired differences of
:data:`FIGURE`'s measures), and ``OUT/control.md`` with the headline measures of both,
the paper's claims, and the section's lateral files per controller
(:mod:`arzsumo_studies.control.files`).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.evaluation.report import MEASURES as EVALUATION_MEASURES
from arzsumo.evaluation.report import Measure, evaluate, markdown
from arzsumo.io import dump_toml, read_toml
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.evaluation import paired_figure
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo.resources import default_scenario
from arzsumo.sweep.evaluate import BASELINE, check_controllers
from arzsumo_studies import checks
from arzsumo_studies.common import RESULTS_DIR, StudyError, seed_text
from arzsumo_studies.control.claims import claims_table
from arzsumo_studies.control.files import MIN_SHARE, files_table
from arzsumo_studies.outputs.pages import publish, write_csv, write_text
from arzsumo_studies.paired import deadlocked_seeds
from arzsumo_studies.recorded import RecordedRuns, recorded_evaluation

log = logging.getLogger(__name__)

NAME = "control"
#: the results page (``research/results/PAGE.md``) this study keeps a block of
PAGE = "control_default"
#: the controllers judged: the open loop, the best constant rate (on the default the
#: least rate won the constant-rate sweep, so it is the held meter), the practitioner's
#: ALINEA and PI-ALINEA, and the paper's three laws
JUDGED = ("open", "held", "alinea", "pi-alinea", "backstepping", "etc", "observer-etc")
#: the experiments the study runs unless told, in order
EXPERIMENTS = ("regulation", "disturbance")
#: the disturbance experiment's [disturbance] table (scenario units): the edge past the
#: merge at 10 km/h for 30 s from the start of control
DISTURBANCE = {"kind": "slowdown", "edge": "down", "speed_kmh": 10.0, "start_s": 0.0,
               "duration_s": 30.0}
#: every experiment and its [disturbance] (None: regulation). ``merge-slowdown`` is the
#: same slowdown on the merge's edge, for an actuator that owns the edge past the merge
#: (the outlet's speed limit, docs/sumo.md)
DISTURBANCES: dict[str, dict | None] = {
    "regulation": None, "disturbance": DISTURBANCE,
    "merge-slowdown": {**DISTURBANCE, "edge": "merge"}}
ALL_EXPERIMENTS = tuple(DISTURBANCES)
#: the deviation measures the study adds to the evaluation's (columns of the runs table)
DEVIATION = (
    Measure("section.deviation.decay_time_s", "decay time to the stationary band", "s"),
    Measure("section.deviation.deviation_integral_s", "integrated deviation norm", "s"),
    Measure("section.deviation.deviation_excess_s", "integrated deviation above the band",
            "s"),
)
_EXTRA = (
    Measure("release_time", "release time (no controller update)", "s",
            lower_is_better=False),
    Measure("section.J_fuel.total", "section J_fuel (paper)", "veh"),
    Measure("section.J_discom.total", "section J_discom (paper)", "veh m^2/s^3"),
)
#: every measure of the per-experiment tables
MEASURES: tuple[Measure, ...] = (*EVALUATION_MEASURES[:1], *DEVIATION,
                                 *EVALUATION_MEASURES[1:], *_EXTRA)
#: the headline measures of OUT/control.md (keys)
HEADLINE = ("network_whole_demand.time_spent_s.total",
            "network_whole_demand.time_spent_s.mainline",
            "network_whole_demand.time_spent_s.ramp",
            "network_whole_demand.ramp_wait_s.p95",
            "network_whole_demand.ramp_wait_s.over_limit",
            "network.throughput_veh_h.section_outlet",
            "section.deviation.deviation_excess_s", "section.deviation.decay_time_s",
            "section.waves.h.band_power_kmh2",
            "section.waves.a.band_power_kmh2", "section.waves.h.growth_per_km",
            "section.waves.a.growth_per_km", "section.speed_oscillation_kmh.h",
            "section.speed_oscillation_kmh.a", "plan_changes", "light_changes",
            "section.TTT.total", "section.total_delay.total", "section.J_fuel.total",
            "section.J_discom.total")
#: the measures of each experiment's figure, ``OUT/<experiment>/control.png`` (keys)
FIGURE = ("network_whole_demand.time_spent_s.total", "network_whole_demand.ramp_wait_s.p95",
          "section.waves.h.band_power_kmh2", "section.waves.a.band_power_kmh2",
          "section.speed_oscillation_kmh.h", "section.speed_oscillation_kmh.a",
          "section.deviation.decay_time_s", "plan_changes")


def experiment_scenario(base: dict, experiment: str) -> dict:
    """The scenario (as written) of ``experiment`` on the base scenario ``base``."""
    data = {k: dict(v) if isinstance(v, dict) else v for k, v in base.items()}
    data.pop("disturbance", None)
    if DISTURBANCES[experiment] is not None:
        data["disturbance"] = dict(DISTURBANCES[experiment])
    data["name"] = f"{base.get('name', 'scenario')}-{experiment}"
    return data


def _cell(r: pd.Series, baseline: bool) -> str:
    """One headline cell: the open loop's own mean [95 % t] over its n seeds; any other
    controller's paired difference against it, mean [95 % t] {95 % bootstrap}
    wins/losses of the seeds paired (the controllers of a study may have run on
    different numbers of seeds so far)."""
    if baseline:
        return f"{r['mean']:.4g} [{r.ci_low:.4g}, {r.ci_high:.4g}] (its mean of {int(r.n)})"
    if not np.isfinite(r.diff_mean):
        return ""
    return (f"{r.diff_mean:+.3g} [{r.diff_ci_low:+.3g}, {r.diff_ci_high:+.3g}]"
            f" {{{r.diff_boot_low:+.3g}, {r.diff_boot_high:+.3g}}}"
            f" {int(r.wins)}/{int(r.losses)} of {int(r.wins + r.losses + r.ties)}")


def headline(tables: dict[str, pd.DataFrame]) -> str:
    """Markdown: per headline measure, the open loop's mean and every other controller's
    paired difference against it in each experiment (:func:`_cell`)."""
    head = ("| measure | unit | controller | "
            + " | ".join(f"{e}: open mean [t]; others minus open [t] {{bootstrap}} w/l "
                         "of pairs"
                         for e in tables) + " |")
    lines = [head, "|---" * (3 + len(tables)) + "|"]
    first = next(iter(tables.values()))
    for key in HEADLINE:
        sel = first[first["measure"] == key]
        for ctrl in sel["controller"]:
            cells = []
            for long in tables.values():
                r = long[(long["measure"] == key) & (long["controller"] == ctrl)]
                if r.empty or not np.isfinite(r["mean"].iloc[0]):
                    cells.append("")
                    continue
                cells.append(_cell(r.iloc[0], baseline=ctrl == BASELINE))
            label = sel[sel["controller"] == ctrl].iloc[0]
            lines.append(f"| {label.label} | {label.unit} | {ctrl} | " + " | ".join(cells)
                         + " |")
    return "\n".join(lines)


@dataclass(frozen=True)
class ControlOptions:
    """What ``arzsumo study control`` runs.

    ``scenario``: the base scenario file (None: the shipped default); ``controllers``
    and ``experiments``: of :data:`JUDGED` (and ALINEA's kin) and :data:`ALL_EXPERIMENTS`;
    ``runs``: the seeds, the record store and how the runs run; ``out``: the study's
    directory (resumable); ``docs`` and ``page``: the results page to regenerate (None:
    none); ``plots``: draw the figures.
    """

    runs: RecordedRuns
    scenario: Path | None = None
    controllers: tuple[str, ...] = JUDGED
    experiments: tuple[str, ...] = EXPERIMENTS
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    page: str = PAGE
    plots: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "controllers", tuple(check_controllers(
            list(self.controllers))))
        checks.all_among(self.experiments, ALL_EXPERIMENTS, "experiments")

    @property
    def base(self) -> Path:
        """The base scenario file."""
        return self.scenario or default_scenario()


@dataclass(frozen=True)
class ControlResult:
    """What the study produced: per experiment its table (``tables``: one row per
    controller and measure), its finished runs (``runs``), the text of ``control.md``,
    and whether every run finished (``complete``)."""

    tables: dict[str, pd.DataFrame]
    runs: dict[str, pd.DataFrame]
    text: str
    complete: bool


def design(opts: ControlOptions) -> list[str]:
    """One line per experiment: its controllers and seeds (``--list``)."""
    return [f"{e}: {', '.join(opts.controllers)} on seeds {seed_text(list(opts.runs.seeds))}"
            for e in opts.experiments]


def write_tables(plots: bool, long: pd.DataFrame, runs: pd.DataFrame,
                 controllers: Sequence[str], where: Path) -> list[tuple[Path, str]]:
    """One experiment's ``control.csv``, ``control.md`` and (plots wanted, two controllers
    or more) ``control.png`` in ``where``; return them as (path, published name). A figure
    not redrawn is removed, so none of an earlier call is left to be published."""
    e = where.name
    files = [(write_csv(long, where / "control.csv"), f"{e}.csv"),
             (write_text(f"# {e}\n\n{markdown(long, BASELINE)}", where / "control.md"),
              f"{e}.md")]
    figure = where / "control.png"
    if plots and len(controllers) > 1:
        paired_figure(figure, long, runs, controllers, BASELINE,
                      [m for m in MEASURES if m.key in FIGURE and m.key in runs.columns])
        files.append((figure, f"{e}.png"))
    else:
        remove_stale_figures(figure)
    return files


def run_control(opts: ControlOptions) -> ControlResult:
    """Both experiments (resumable), the deviation measures, the tables."""
    controllers, runs = list(opts.controllers), opts.runs
    _, base = read_toml(opts.base, "scenario", StudyError)
    ok, tables, finished_runs, counts, files = True, {}, {}, [], []
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        for e in opts.experiments:
            path = write_text(dump_toml(experiment_scenario(base, e)),
                              out / "scenarios" / f"{e}.toml")
            found, finished = recorded_evaluation(runs, path, controllers, out / e)
            ok &= finished
            counts.append(f"{e}: {len(found)} of {len(controllers) * len(runs.seeds)} "
                          "runs finished")
            stuck = deadlocked_seeds(found, controllers)
            if stuck:
                log.warning("%s: seeds %s left out: SUMO deadlocked before control "
                            "under every controller", e, seed_text(stuck))
                noun = "seeds" if len(stuck) > 1 else "seed"
                counts.append(f"{noun} {seed_text(stuck)} left out of the {e} tables (SUMO "
                              "deadlocked before control under every controller, the open "
                              "loop included)")
                found = found[~found["seed"].isin(stuck)]
            if found.empty:      # a report before any run of this experiment finished
                log.warning("no finished %s runs yet: its tables are left out", e)
                continue
            measures = [m for m in MEASURES if m.key in found.columns]
            tables[e] = evaluate(found, controllers, BASELINE, measures)
            finished_runs[e] = found
            files += write_tables(opts.plots, tables[e], found, controllers, out / e)
        if not tables and not runs.report:
            log.error("no run finished: no tables; the failures are in %s", opts.out)
            return ControlResult({}, {}, "", False)
        if not tables:
            raise StudyError(f"--out = {opts.out} has no finished runs yet; allowed: a run "
                             "without --report, or --records with a store that holds some")
        text = _page_text(opts, tables, finished_runs, counts)
        write_text(text, out / "control.md")
        if opts.docs is not None:
            name = base.get("name", "the scenario")
            title = "the default" if name == "default" else name
            publish(opts.docs, opts.page, NAME, f"The controllers on {title} in SUMO", text,
                    files)
    return ControlResult(tables, finished_runs, text, ok)


def _page_text(opts: ControlOptions, tables: dict[str, pd.DataFrame],
               finished_runs: dict[str, pd.DataFrame], counts: list[str]) -> str:
    """``control.md``: the headline, the paper's claims, the lateral files."""
    seeds = list(opts.runs.seeds)
    text = (f"Controllers {', '.join(opts.controllers)} on seeds {seed_text(seeds)}, "
            f"paired against the open loop (`arzsumo study {NAME}`); "
            + "; ".join(counts) + ".\n\n" + headline(tables))
    found = claims_table(finished_runs, seeds)
    if found:
        text += ("\n\nThe paper's section-5 claims, as SUMO tests them (95 % t intervals "
                 "of the paired differences):\n\n" + found)
    for e, runs in finished_runs.items():
        text += (f"\n\nThe section's lateral files, {e} (files holding at least "
                 f"{MIN_SHARE:.0%} of a class's samples, and the largest gap between "
                 "their mean speeds: a class-level average is the stream's only while "
                 "its files ride at one speed):\n\n"
                 + files_table(runs, list(opts.controllers)))
    return text
