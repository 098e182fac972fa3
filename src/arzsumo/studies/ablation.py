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

import argparse
import copy
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.evaluation.report import MEASURES as EVALUATION_MEASURES
from arzsumo.io import dump_toml
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import publish, write_csv, write_text
from arzsumo.studies.common import (
    EXIT_SOME_FAILED,
    FORMER_DEFAULT,
    StudyError,
    add_output,
    add_runs,
    fixed_cycle,
    plots_wanted,
    scenario_data,
    seed_text,
    shipped_scenario,
)
from arzsumo.sweep.evaluate import (
    BASELINE,
    OPEN_LOOP_INERT,
    PLACEMENT_ONLY,
    inert_for,
    run_evaluation,
)
from arzsumo.sweep.worker import FINISHED

log = logging.getLogger(__name__)

NAME = "ablation"
#: the results page (``docs/results/PAGE.md``) this study keeps a block of
PAGE = "control_in_sumo"
#: prediction horizon of the ``delay`` step, s: the measured dead time from a new plan to
#: the section's outflow (10-14 s) plus the mean wait for the next cycle (meter-dynamics)
PREDICTION_S = 14.0
#: the step every other one builds on, and whose open loop they may borrow
IDENTIFIED = "identified"
#: the measures of the ablation table (evaluation keys, in the evaluation's labels)
MEASURES = ("network_whole_demand.time_spent_s.total", "section.speed_spread_kmh.h",
            "section.speed_spread_kmh.a", "section.speed_oscillation_kmh.h",
            "section.speed_oscillation_kmh.a", "network.time_loss_s.total", "plan_changes")


@dataclass(frozen=True)
class Step:
    """One step: its name, what it switches on, and where its changes come from.

    ``keys``: ``table.key`` (or a whole ``table``) taken from the former default (lateral_files);
    ``values``: ``table.key`` -> value set explicitly; ``laws``: the controllers compared
    with the open loop; ``legacy``: the [model] and [equilibrium] of
    ``legacy_default.toml``; ``after``: the step it builds on when not the one listed
    before it (a side branch).
    """

    name: str
    change: str
    keys: tuple[str, ...] = ()
    values: Mapping[str, Any] = field(default_factory=dict)
    laws: tuple[str, ...] = ("backstepping", "etc")
    after: str | None = None
    legacy: bool = False


STEPS = (
    Step("scenario", "congested SUMO scenario, the paper's calibrated model "
         "(legacy_default.toml)", legacy=True),
    Step(IDENTIFIED, "model identified from SUMO: scenarios/default.toml",
         laws=("alinea", "backstepping", "etc")),
    Step("estimator", "ASM estimate from loops every 250 m + AV probes",
         keys=("sensing.kinds", "sensing.loop_spacing_m", "estimation.method")),
    Step("reference", "deviations from the warm-up mean state, not the model's equilibrium",
         keys=("estimation.reference", "estimation.reference_window_s")),
    Step("saturation", "|U| <= 20 % of q*, rate <= 100 veh/h per s, ramp bound, anti-windup",
         keys=("actuation.u_max_fraction", "actuation.u_rate_max_veh_h_s",
               "actuation.ramp_bound", "actuation.anti_windup")),
    Step("design", "ETC parameters designed for the identified model (design-check --auto; "
         "ETC only: backstepping is that of `saturation`)", keys=("design",),
         laws=("etc",)),
    Step("delay", f"laws on the state predicted {PREDICTION_S:g} s ahead (delay predictor)",
         values={"actuation.delay_compensation_s": PREDICTION_S}),
    Step("meter", "one vehicle per green at a release rate, 2 s yellow (on `design`, the "
         "default; its own open loop)", keys=("sumo.meter_mode", "sumo.meter_clearance_s"),
         after="design"),
)
STEP_NAMES = tuple(s.name for s in STEPS)


def controller_side() -> tuple[str, ...]:
    """The scenario tables no open loop reads (the evaluation's
    :data:`~arzsumo.sweep.evaluate.OPEN_LOOP_INERT`): the PDE laws' side the steps switch
    on. ALINEA's table stays: ``identified`` runs it."""
    return tuple(t for t in OPEN_LOOP_INERT if "." not in t
                 and t not in ("name", "description"))


def base_scenario(default: Mapping[str, Any]) -> dict[str, Any]:
    """The default's tables without its controller side and meter realisation."""
    side = controller_side()
    return fixed_cycle({k: copy.deepcopy(v) for k, v in default.items() if k not in side})


def step(name: str) -> Step:
    """The step called ``name``."""
    if name not in STEP_NAMES:
        raise StudyError(f"--steps: {name!r} is not allowed: one of {', '.join(STEP_NAMES)}")
    return STEPS[STEP_NAMES.index(name)]


def changes(s: Step, default: Mapping[str, Any]) -> dict[str, Any]:
    """``table.key`` -> value of the changes step ``s`` itself switches on."""
    out: dict[str, Any] = {}
    for key in s.keys:
        table, _, k = key.partition(".")
        found = default.get(table, {})
        for name, value in (found.items() if not k else [(k, found.get(k))]):
            if value is None:
                raise StudyError(f"the former default (lateral_files) has no "
                                 f"{table}.{name}: the ablation step {s.name!r} switches it on")
            out[f"{table}.{name}"] = copy.deepcopy(value)
    return out | dict(s.values)


def chain(name: str) -> list[Step]:
    """The steps after ``identified`` whose changes step ``name`` carries, in order."""
    if name in ("scenario", IDENTIFIED):
        return []
    s = step(name)
    upto = STEP_NAMES.index(s.after or name)
    main = [x for x in STEPS[STEP_NAMES.index(IDENTIFIED) + 1:upto + 1] if x.after is None]
    return main + ([s] if s.after else [])


def acts_on_open_loop(key: str) -> bool:
    """Whether scenario key ``key`` can change an open-loop SUMO run (the evaluation's
    rule: :func:`~arzsumo.sweep.evaluate.inert_for`, and the model when SUMO fills the
    road itself: :data:`~arzsumo.sweep.evaluate.PLACEMENT_ONLY`, checked by the
    evaluation when it borrows)."""
    inert = set(inert_for(BASELINE)) | set(PLACEMENT_ONLY)
    return not (key in inert or key.partition(".")[0] in inert)


def step_scenario(name: str, default: Mapping[str, Any] | None = None,
                  legacy: Mapping[str, Any] | None = None) -> tuple[dict[str, Any], str | None]:
    """The scenario tables of step ``name`` and the step whose open loop it borrows."""
    default = default if default is not None else scenario_data(shipped_scenario(FORMER_DEFAULT))
    data = base_scenario(default)
    flat: dict[str, Any] = {}
    if step(name).legacy:
        legacy = legacy if legacy is not None else \
            scenario_data(shipped_scenario("legacy_default.toml"))
        flat = {f"{t}.{k}": v for t in ("model", "equilibrium") for k, v in legacy[t].items()}
        data.update({t: {} for t in ("model", "equilibrium")})
    for s in chain(name):
        flat.update(changes(s, default))
    for dotted, value in flat.items():
        table, _, key = dotted.partition(".")
        data.setdefault(table, {})[key] = copy.deepcopy(value)
    data["name"] = f"ablation-{name}"
    borrow = IDENTIFIED if name != IDENTIFIED and not any(map(acts_on_open_loop, flat)) \
        else None
    return data, borrow


def run_order(names: Sequence[str]) -> list[str]:
    """``names`` with ``identified`` first: the others may borrow its open loop."""
    return sorted(dict.fromkeys(names), key=lambda n: n != IDENTIFIED)


def controllers_of(name: str, borrow: str | None) -> list[str]:
    """The controllers an evaluation of step ``name`` runs (the open loop first, unless
    borrowed)."""
    laws = list(step(name).laws)
    return laws if borrow else [BASELINE, *laws]


def run_step(name: str, out: Path, seeds: Sequence[int], args: argparse.Namespace) -> bool:
    """Write step ``name``'s scenario and run its evaluation (resumable); whether every
    run finished."""
    data, borrow = step_scenario(name)
    path = out / "steps" / f"{name}.toml"
    write_text(dump_toml(data), path)
    if borrow and not (out / borrow / "summaries.parquet").is_file():
        raise StudyError(f"step {name!r} takes the open loop of {borrow!r}, which is not "
                         f"in {out}; allowed: --steps with {borrow} (it runs first)")
    res = run_evaluation(path, controllers_of(name, borrow), list(seeds), out=out / name,
                         workers=args.workers, scheduler=args.scheduler,
                         progress=not args.quiet, plots=plots_wanted(args),
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


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The ablation's options."""
    parser.add_argument("--steps", default=",".join(STEP_NAMES),
                        help="comma-separated steps to run (identified runs first)")
    add_runs(parser, seeds="1-10")
    parser.add_argument("--report", action="store_true",
                        help="run nothing: assemble the table from the steps in --out")
    parser.add_argument("--legacy", type=Path, metavar="CSV",
                        help="an earlier evaluation.csv listed first as step 'legacy'")
    add_output(parser, NAME, PAGE)


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


def run(args: argparse.Namespace) -> int:
    """Run the steps asked for, then write the table (and the page with ``--docs``)."""
    names = run_order([n.strip() for n in args.steps.split(",") if n.strip()])
    for name in names:
        step(name)
    if args.list:
        for name in names:
            _, borrow = step_scenario(name)
            print(f"{name}: {', '.join(controllers_of(name, borrow))} on seeds "
                  f"{seed_text(args.seeds)}"
                  + (f"; open loop from {borrow}" if borrow else ""))
        return 0
    ok = True
    with resumable_dir(args.out, f"study-{NAME}") as out:
        if not args.report:
            for name in names:
                ok = run_step(name, out, args.seeds, args) and ok
        table = report(out, args.legacy)
        write_csv(table, out / "ablation.csv")
        write_text(markdown(table), out / "ablation.md")
        if args.docs is not None:
            body, files = _page(out, table)
            publish(args.docs, PAGE, NAME, "Control in SUMO", body, files)
    print(markdown(table))
    return 0 if ok else EXIT_SOME_FAILED
