"""The ablation of the PDE controllers in SUMO, one change at a time
(``arzsumo study ablation``).

The steps start from the former default scenario (lateral_files) without its controller side (the
tables the evaluation counts as inert for an open loop: [sensing], [estimation],
[actuation], [design]; :data:`arzsumo.sweep.evaluate.OPEN_LOOP_INERT`) and without its meter
realisation (the plain fixed cycle), and switch the default's controller side on again
one change after the other (cumulative):

=============  ===========================================================================
step           change (on the step before; controllers besides the open loop)
=============  ===========================================================================
scenario       the model of ``legacy_default.toml`` (the paper's calibrated FD) instead of
               the identified one: the scenario separated from the identification
identified     none: ``default.toml``'s SUMO scenario and identified model (ALINEA too)
estimator      the laws on the ASM estimate from loops every 250 m and AV probes
reference      deviations from the warm-up's mean state, not the model's equilibrium
saturation     \\|U\\| and its rate bounded, the ramp bound, anti-windup
design         the ETC parameters designed for the identified model (ETC only)
delay          the laws on the state predicted :data:`PREDICTION_S` s ahead
meter          one vehicle per green at a release rate with a yellow (on ``design``)
=============  ===========================================================================

Every change but ``delay``'s is read from the former default (lateral_files), so the
ablation is that of its controller side. Each step is an evaluation (:func:`~arzsumo.sweep.
evaluate.run_evaluation`, paired by seed against the open loop) of its scenario, written
to ``OUT/steps/<step>.toml``, into ``OUT/<step>/``. A step whose changes do not act on an
open loop (the evaluation's inert tables, or the model when SUMO fills the road itself)
takes the open-loop runs of ``identified`` (``baseline_from``), which runs first.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from arzsumo.evaluation.report import MEASURES as EVALUATION_MEASURES
from arzsumo.io import dump_toml
from arzsumo.outdir import resumable_dir
from arzsumo.sweep.evaluate import BASELINE, run_evaluation
from arzsumo.sweep.worker import FINISHED
from arzsumo_studies import checks
from arzsumo_studies.ablation.steps import (  # noqa: F401 (the steps, re-exported)
    IDENTIFIED,
    PREDICTION_S,
    STEP_NAMES,
    STEPS,
    Step,
    acts_on_open_loop,
    base_scenario,
    chain,
    changes,
    controller_side,
    controllers_of,
    run_order,
    step,
    step_scenario,
)
from arzsumo_studies.common import (  # noqa: F401 (scenario_data, shipped_scenario: re-exported)
    EXIT_SOME_FAILED,
    RESULTS_DIR,
    StudyError,
    scenario_data,
    seed_text,
    shipped_scenario,
)
from arzsumo_studies.outputs.pages import publish, write_csv, write_text

log = logging.getLogger(__name__)

NAME = "ablation"
#: the results page (``research/results/PAGE.md``) this study keeps a block of
PAGE = "control_in_sumo"
#: the measures of the ablation table (evaluation keys, in the evaluation's labels)
MEASURES = ("network_whole_demand.time_spent_s.total", "section.speed_spread_kmh.h",
            "section.speed_spread_kmh.a", "section.speed_oscillation_kmh.h",
            "section.speed_oscillation_kmh.a", "network.time_loss_s.total", "plan_changes")


def run_step(name: str, out: Path, opts: AblationOptions, progress: bool = True) -> bool:
    """Write step ``name``'s scenario and run its evaluation (resumable) on
    ``opts.seeds``; whether every run finished."""
    data, borrow = step_scenario(name)
    path = out / "steps" / f"{name}.toml"
    write_text(dump_toml(data), path)
    if borrow and not (out / borrow / "summaries.parquet").is_file():
        raise StudyError(f"step {name!r} takes the open loop of {borrow!r}, which is not "
                         f"in {out}; allowed: --steps with {borrow} (it runs first)")
    res = run_evaluation(path, controllers_of(name, borrow), list(opts.seeds),
                         out=out / name, workers=opts.workers, scheduler=opts.scheduler,
                         progress=progress, plots=opts.plots,
                         baseline_from=out / borrow if borrow else None)
    table = res.sweep.table if res.sweep is not None else None
    return table is None or bool(table["status"].isin(FINISHED).all())


def _label(key: str) -> str:
    m = next(m for m in EVALUATION_MEASURES if m.key == key)
    return f"{m.label} ({m.unit})"


def _canonical(measure: str) -> str:
    """An evaluation CSV's measure name under its current key (an older CSV may use an
    alias)."""
    return next((m.key for m in EVALUATION_MEASURES if measure in m.aliases), measure)


def report(out: Path, legacy_csv: Path | None = None) -> pd.DataFrame:
    """One row per (step, controller, measure) found: the mean and the paired difference
    against the open loop with its 95 % t interval (``legacy_csv``: an earlier
    evaluation listed first as step ``legacy``)."""
    sources = [("legacy", "an earlier evaluation", legacy_csv)] if legacy_csv else []
    sources += [(s.name, s.change, out / s.name / "evaluation.csv") for s in STEPS]
    rows = []
    for name, change, csv in sources:
        if csv is None or not Path(csv).is_file():
            continue
        df = pd.read_csv(csv)
        df["measure"] = df["measure"].map(_canonical)
        for r in df[df["measure"].isin(MEASURES)].itertuples(index=False):
            rows.append({"step": name, "change": change, "controller": r.controller,
                         "measure": r.measure, "label": _label(r.measure), "n": r.n,
                         "mean": r.mean, "diff_mean": r.diff_mean,
                         "diff_ci_low": r.diff_ci_low, "diff_ci_high": r.diff_ci_high,
                         "wins": r.wins, "losses": r.losses})
    return pd.DataFrame(rows)


def markdown(table: pd.DataFrame) -> str:
    """Steps x controllers; per measure 'mean (minus open [95 % CI])'."""
    lines = ["| step | controller | " + " | ".join(map(_label, MEASURES)) + " |",
             "|" + "---|" * (2 + len(MEASURES))]
    if table.empty:
        return "\n".join(lines)
    for (name, ctrl), g in table.groupby(["step", "controller"], sort=False):
        cells = []
        for key in MEASURES:
            r = g[g["measure"] == key]
            if r.empty or pd.isna(r.iloc[0]["mean"]):
                cells.append("")
                continue
            r = r.iloc[0]
            if ctrl == BASELINE or pd.isna(r["diff_mean"]):   # no paired open loop
                cells.append(f"{r['mean']:.3g}")
            else:
                cells.append(f"{r['mean']:.3g} ({r['diff_mean']:+.3g} "
                             f"[{r['diff_ci_low']:+.3g}, {r['diff_ci_high']:+.3g}])")
        lines.append(f"| {name} | {ctrl} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def step_seeds(out: Path) -> dict[str, list[int]]:
    """Per step with an evaluation in ``out``, the seeds of its finished runs: those its
    rows of the table report (``--report`` reads steps run earlier, on their seeds)."""
    found: dict[str, list[int]] = {}
    for s in STEPS:
        runs = out / s.name / "summaries.parquet"
        if (out / s.name / "evaluation.csv").is_file() and runs.is_file():
            df = pd.read_parquet(runs, columns=["seed", "status"])
            found[s.name] = sorted({int(v) for v in df.loc[df["status"].isin(FINISHED),
                                                            "seed"]})
    return found


def seeds_phrase(by_step: Mapping[str, list[int]]) -> str:
    """``seeds 1-10`` when every step has the same seeds, else each step's."""
    distinct = {tuple(v) for v in by_step.values()}
    if not distinct:
        return "the seeds of each step's evaluation"
    if len(distinct) == 1:
        return f"seeds {seed_text(list(distinct.pop()))}"
    return "seeds " + "; ".join(f"{name}: {seed_text(v)}" for name, v in by_step.items())


def _page(out: Path, table: pd.DataFrame) -> tuple[str, list]:
    """The page body and the files it publishes."""
    files: list = [(out / "ablation.csv", f"{PAGE}.csv")]
    steps = []
    for s in STEPS:
        if (out / s.name / "evaluation.csv").is_file():
            files += [(out / s.name / "evaluation.csv", f"{s.name}.csv"),
                      (out / s.name / "evaluation.md", f"{s.name}.md"),
                      (out / "steps" / f"{s.name}.toml", f"steps/{s.name}.toml")]
            steps.append(f"[{s.name}]({PAGE}/{s.name}.md)")
    body = (f"Each step switches on one more change of the default's controller side and "
            f"is evaluated on {seeds_phrase(step_seeds(out))} (`arzsumo study ablation`). "
            f"Cells: mean (controller minus open loop, same seed [95 % t interval]).\n\n"
            f"{markdown(table)}\n\nTable: [{PAGE}.csv]({PAGE}/{PAGE}.csv); the "
            f"evaluations: {', '.join(steps)}; their scenarios in [steps/]({PAGE}/steps/).")
    return body, files


@dataclass(frozen=True)
class AblationOptions(checks.Shared):
    """What the ablation runs and reads, and where it writes.

    Parameters
    ----------
    steps : tuple of str
        The steps to run, of :data:`STEP_NAMES` (``identified`` runs first).
    seeds : tuple of int
        SUMO seeds of every step's evaluation.
    report : bool
        Run nothing: assemble the table from the steps in ``out``.
    legacy : Path, optional
        An earlier ``evaluation.csv`` listed first as step ``legacy``.
    plots : bool
        Draw the evaluations' figures.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    steps: tuple[str, ...] = STEP_NAMES
    seeds: tuple[int, ...] = tuple(range(1, 11))
    report: bool = False
    legacy: Path | None = None
    out: Path = RESULTS_DIR / NAME
    plots: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in run_order(self.steps):
            step(name)
        checks.seeds(self.seeds)


@dataclass(frozen=True)
class AblationResult:
    """The ablation's outcome: the exit ``code`` (0; 4 when a run did not finish), the
    ``table`` (one row per step, controller and measure), its markdown ``text`` and the
    ``files`` written."""

    code: int
    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def design(opts: AblationOptions) -> list[str]:
    """Per step, in run order: its controllers, seeds and the open loop it borrows."""
    lines = []
    for name in run_order(opts.steps):
        _, borrow = step_scenario(name)
        lines.append(f"{name}: {', '.join(controllers_of(name, borrow))} on seeds "
                     f"{seed_text(list(opts.seeds))}"
                     + (f"; open loop from {borrow}" if borrow else ""))
    return lines


def run_ablation(opts: AblationOptions, *, progress: bool = True) -> AblationResult:
    """Run the steps asked for, then write the table (and the page with ``opts.docs``).

    Parameters
    ----------
    opts : AblationOptions
        The ablation's options.
    progress : bool, optional
        Show a progress bar while the runs run.

    Returns
    -------
    AblationResult
        The exit code, the table and the files written (``ablation.csv``,
        ``ablation.md`` and each step's evaluation in ``opts.out``).
    """
    ok = True
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        if not opts.report:
            for name in run_order(opts.steps):
                ok = run_step(name, out, opts, progress) and ok
        table = report(out, opts.legacy)
        text = markdown(table)
        files = (write_csv(table, out / "ablation.csv"), write_text(text, out / "ablation.md"))
        if opts.docs is not None:
            body, published = _page(out, table)
            publish(opts.docs, PAGE, NAME, "Control in SUMO", body, published)
    return AblationResult(0 if ok else EXIT_SOME_FAILED, table, text, files)
