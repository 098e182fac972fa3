"""Which piece of the controllers' configuration matters, one at a time
(``arzsumo study control-ablation``).

The control study (``arzsumo study control``) runs the PDE laws
with every piece the former default's ablation found needed: the ASM estimate rather than
raw cells, deviations from the warm-up's state, saturation with anti-windup, the meter
releasing one vehicle per green. This study takes one piece away at a time (and adds the
dead-time predictor, which the configuration lacks) and pairs each step, seed by seed,
with the full configuration's runs of the same controller:

==================  ==============================================================
step                change on the experiment's scenario
==================  ==============================================================
raw-cells           the laws on SUMO's Edie cells of every vehicle (no estimator)
equilibrium         deviations from the model's equilibrium, not the warm-up's state
no-saturation       no bound on U or its rate, no ramp bound, no anti-windup
fixed-cycle         the meter as a fixed cycle of green shares (no one-per-green)
predictor           the laws on the state predicted :data:`PREDICTION_S` s ahead
predictor-measured  the same, :data:`MEASURED_DEAD_TIME_S` s ahead: the meter's dead
                    time measured on the default (``arzsumo study meter-delay``)
wave-matched        the laws (and twins) on the model whose lambda_4 is SUMO's
                    measured wave speed :data:`WAVE_SPEED_KMH`, same equilibrium
                    (:func:`arzsumo_studies.measures.wave_match.wave_matched`)
dead-band           the ETC's trigger with the noise dead band :data:`DEAD_BAND_KMH`
                    (``[design] noise_sd_kmh``; backstepping does not read it)
power-law           the laws (and twins) on the shipped default's power-law model,
                    equilibrium and ``[design]`` (``ablation_steps._power_law``)
paper-trigger       the ETC's trigger as in the paper: no dead band measured on the
                    estimate (``[design] noise_from_estimate`` off)
unit-gain           the laws on the paper's unit actuator: ``[actuation] meter_gain`` 1
quarter-law         the laws' command to the meter :data:`QUARTER` times smaller
                    (``[actuation] meter_gain`` times :data:`QUARTER`): their swings
                    inside the meter's range (``ablation_steps._quarter_law``)
paper-eta           the ETC's dynamic variable m forgetting at the paper's rate,
                    ``[design] eta`` = :data:`PAPER_ETA`
speed-limit         the laws on the outlet's speed limit (mainstream control, the same
                    boundary input q(L) - q*) instead of the ramp meter
                    (``[actuation]`` :data:`SPEED_LIMIT`)
acted-trigger       the ETC's trigger and m weighing d against V_U, the least energy of
                    a state giving the law's U (``[design] trigger_energy = "acted"``)
band-trigger        the ETC's events whenever the hold error leaves the noise band
                    measured on the estimate (``[design] trigger = "band"``)
realised-gain       the outlet's speed-limit gain at what backstepping realised there
                    (:data:`REALISED_SPEED_GAIN`; joined with speed-limit)
==================  ==============================================================

Steps joined by ``+`` are one step with each change, in order
(``speed-limit+acted-trigger``: the ETC with the acted trigger on the outlet's speed
limit), paired like any other. The steps and their constants live in
:mod:`arzsumo_studies.control.ablation_steps` (re-exported here).

The steps change the regulation experiment, or with ``--experiment disturbance`` the
disturbance experiment (then against the control study's disturbance runs). Each step is
an evaluation (:func:`~arzsumo.sweep.evaluate.run_evaluation`) into ``OUT/<step>/``
(``OUT/<step>-disturbance/``). A step that does not act on an open loop borrows the open
loop of the control study (``--control DIR``: its ``--out``, or its record store, whose
open-loop records are then restored into ``OUT/control-open/``); ``fixed-cycle`` changes
the plant and runs its own, and so do ``wave-matched`` and ``power-law`` where the
model's speeds place the section (``ablation_steps.own_open_loop``). The table gives
each step minus the full configuration and minus the open loop.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from arzsumo.errors import ArzsumoError, require
from arzsumo.evaluation.report import Measure
from arzsumo.io import dump_toml, read_toml
from arzsumo.outdir import resumable_dir
from arzsumo.resources import default_scenario
from arzsumo.scenario import scenario_from_dict
from arzsumo.sweep.evaluate import BASELINE, evaluation_spec
from arzsumo.sweep.evaluate import KIND as EVALUATION_KIND
from arzsumo.sweep.spec import RunSpec
from arzsumo.sweep.worker import FINISHED
from arzsumo_studies import checks
from arzsumo_studies.common import RESULTS_DIR, StudyError, seed_text
from arzsumo_studies.control import study as control
from arzsumo_studies.control.ablation_steps import (
    DEAD_BAND_KMH,
    DEFAULT_STEPS,
    JOIN,
    MEASURED_DEAD_TIME_S,
    PAPER_ETA,
    POWER_LAW_STEPS,
    PREDICTION_S,
    QUARTER,
    REALISED_SPEED_GAIN,
    SPEED_LIMIT,
    STEPS,
    WAVE_SPEED_KMH,
    apply_step,
    default_steps,
    describe,
    is_step,
    own_open_loop,
)
from arzsumo_studies.outputs.pages import publish, write_text
from arzsumo_studies.paired import paired_cell, seed_values
from arzsumo_studies.recorded import RecordedRuns, recorded_evaluation
from arzsumo_studies.records import copy_records, is_store, records_table

NAME = "control-ablation"
#: the results page this study keeps a block of (the control study's)
PAGE = control.PAGE
#: the laws ablated
LAWS = ("backstepping", "etc")
#: the laws a step may be run on (``--laws``): those and the observer-based ETC
ALL_LAWS = (*LAWS, "observer-etc")
#: the measures of the ablation table (keys of the control study's measures)
KEYS = ("network_whole_demand.time_spent_s.total", "network_whole_demand.ramp_wait_s.p95",
        "section.deviation.deviation_excess_s", "section.deviation.decay_time_s",
        "section.waves.h.band_power_kmh2", "section.waves.a.band_power_kmh2",
        "section.speed_oscillation_kmh.h", "section.speed_oscillation_kmh.a",
        "section.waves.h.short_power_kmh2", "section.waves.h.growth_per_km",
        "plan_changes", "triggers")


def step_name(step: str, experiment: str = "regulation") -> str:
    """The name of a step's evaluation (its directory under ``--out`` and in the record
    store): the step's own in the regulation experiment, suffixed in another."""
    return step if experiment == "regulation" else f"{step}-{experiment}"


def step_scenario(base: dict, step: str, experiment: str = "regulation") -> dict:
    """The control study's ``experiment`` scenario of ``base`` with ``step``'s change."""
    data = control.experiment_scenario(base, experiment)
    data = apply_step(step, {k: dict(v) if isinstance(v, dict) else v
                             for k, v in data.items()})
    data["name"] = f"{base.get('name', 'scenario')}-ablation-{step_name(step, experiment)}"
    return data


def measures() -> list[Measure]:
    return [next(m for m in control.MEASURES if m.key == k) for k in KEYS]


def _cells(a_runs: pd.DataFrame, a: str, b_runs: pd.DataFrame, b: str,
           seeds: list[int]) -> list[str]:
    """Per measure, ``a`` of ``a_runs`` minus ``b`` of ``b_runs``, paired by seed:
    mean [95 % t] {95 % bootstrap} wins/losses of ``a`` (empty where there are too few
    pairs)."""
    return [paired_cell(seed_values(a_runs, m, a, seeds), seed_values(b_runs, m, b, seeds),
                        lower_is_better=m.lower_is_better, bootstrap=True)
            for m in measures()]


def _ran(runs: pd.DataFrame, laws: Sequence[str]) -> list[str]:
    """The ``laws`` of which ``runs`` (a step's evaluation) holds a finished run: a step
    run on some laws only (``--laws``, each invocation its own) shows no empty rows."""
    done = runs.loc[runs["status"].isin(FINISHED)] if "status" in runs.columns else runs
    return [law for law in laws if law in set(done["controller"])]


def table(steps: dict[str, pd.DataFrame], full: pd.DataFrame | None, seeds: list[int],
          laws: Sequence[str] = LAWS, own_open: frozenset[str] | None = None) -> str:
    """Markdown: per step, law and measure, the step minus the full configuration and the
    step minus the open loop of its evaluation, paired by seed (mean [95 % t]
    wins/losses of the step); first, the full configuration minus the open loop, where a
    step borrowed the control study's open loop (``own_open``: the steps that ran their
    own; None: those :data:`STEPS` flags). ``full`` None: the steps against the open
    loop only."""
    lines = ["| step | law | minus | " + " | ".join(f"{m.label} ({m.unit})"
                                                  for m in measures()) + " |",
             "|---" * (3 + len(KEYS)) + "|"]
    own = own_open if own_open is not None else frozenset(s for s in STEPS if STEPS[s][2])
    borrowed = next((r for s, r in steps.items() if s not in own
                     and BASELINE in set(r["controller"])), None)
    if borrowed is not None and full is not None:
        for law in laws:
            lines.append(f"| full | {law} | open | "
                         + " | ".join(_cells(full, law, borrowed, BASELINE, seeds)) + " |")
    for step, runs in steps.items():
        for law in _ran(runs, laws):
            if full is not None:
                lines.append(f"| {step} | {law} | full | "
                             + " | ".join(_cells(runs, law, full, law, seeds)) + " |")
            if BASELINE in set(runs["controller"]):
                lines.append(f"| {step} | {law} | open | "
                             + " | ".join(_cells(runs, law, runs, BASELINE, seeds)) + " |")
    return "\n".join(lines)


def step_scenarios(base: dict, steps: Sequence[str], experiment: str,
                   user: str) -> dict[str, dict]:
    """Every step's scenario, each checked as a scenario; a StudyError naming the first
    step whose change the base scenario does not admit."""
    out = {}
    for s in steps:
        try:
            out[s] = step_scenario(base, s, experiment)
            scenario_from_dict(out[s], f"{user} ({s})")
        except ArzsumoError as exc:
            raise StudyError(f"--steps = {s!r} is not allowed on --scenario = {user}: "
                             f"{exc}; allowed: the other steps") from None
    return out


@dataclass(frozen=True)
class AblationOptions:
    """What ``arzsumo study control-ablation`` runs.

    ``runs``: the seeds, the record store and how the runs run; ``scenario``: the control
    study's base scenario (None: the shipped default); ``control``: the control study's
    ``--out`` or record store (its runs of ``experiment`` are the full configuration,
    its open loop the steps' that borrow one); ``full``: where the full configuration's
    runs are instead (another store of the same study); ``without_full``: compare the
    steps with the open loop only (no full configuration needed);
    ``steps`` of :data:`STEPS` (None: the :func:`default_steps` the scenario admits),
    ``laws`` of :data:`ALL_LAWS`; ``out``, ``docs``: where the
    study writes (None: no page); ``page``: the results page under ``docs`` that gets
    the table (the control study's page of the same scenario).
    """

    runs: RecordedRuns
    scenario: Path | None = None
    control: Path = RESULTS_DIR / control.NAME
    full: Path | None = None
    without_full: bool = False
    experiment: str = "regulation"
    steps: tuple[str, ...] | None = None
    laws: tuple[str, ...] = LAWS
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    page: str = PAGE

    def __post_init__(self) -> None:
        checks.among(self.experiment, control.ALL_EXPERIMENTS, "experiment")
        require(self.steps is None
                or (len(self.steps) > 0 and all(is_step(s) for s in self.steps)), "steps",
                self.steps, "at least one of " + ", ".join(STEPS) + ", or several joined "
                f"by {JOIN}", StudyError)
        checks.all_among(self.laws, ALL_LAWS, "laws")

    @property
    def base(self) -> Path:
        """The control study's base scenario file."""
        return self.scenario or default_scenario()

    def chosen_steps(self) -> tuple[str, ...]:
        """The steps to run: ``steps``, or those the base scenario admits by default."""
        if self.steps is not None:
            return self.steps
        return default_steps(read_toml(self.base, "scenario", StudyError)[1])


@dataclass(frozen=True)
class AblationResult:
    """The table (Markdown) and whether every step's runs finished."""

    text: str
    complete: bool


def design(opts: AblationOptions) -> list[str]:
    """One line per step: what it changes, the laws and seeds (``--list``)."""
    return [f"{s}: {describe(s)}; {', '.join(opts.laws)} on seeds "
            f"{seed_text(list(opts.runs.seeds))}" for s in opts.chosen_steps()]


def full_configuration(runs_dir: Path, scenario: Path, laws: Sequence[str],
                       seeds: Sequence[int], user: str) -> pd.DataFrame:
    """The finished runs of ``laws`` on ``seeds`` that the control study's directory or
    store ``runs_dir`` (one experiment's) holds of ``scenario``; a StudyError naming
    ``user`` (the option as given, ``--control = 'DIR'``) if one lacks."""
    runs = records_table(evaluation_spec(scenario, laws, seeds).runs(), runs_dir)
    missing = runs.loc[~runs["status"].isin(FINISHED), "run_id"].tolist()
    if missing:
        raise StudyError(f"{user} is not allowed: it has no finished "
                         f"{runs_dir.name} run {missing[0]} of this scenario; allowed: the "
                         "--out or the record store of arzsumo study control with these "
                         "laws and seeds")
    return runs


def open_loop_runs(control_runs: Path, runs: Sequence[RunSpec], here: Path) -> Path:
    """Where the steps borrow the control study's open loop from: its directory, or, for
    a record store, ``here``, where the store's open-loop ``runs`` are restored."""
    if not is_store(control_runs):
        return control_runs
    with resumable_dir(here, EVALUATION_KIND) as claimed:
        copy_records(runs, control_runs, claimed)
    return here


def run_ablation(opts: AblationOptions) -> AblationResult:
    """Every step's evaluation (resumable), then the table against the full configuration."""
    _, base = read_toml(opts.base, "scenario", StudyError)
    steps = list(opts.steps if opts.steps is not None else default_steps(base))
    laws, seeds = list(opts.laws), list(opts.runs.seeds)
    experiment = opts.experiment
    control_runs = Path(opts.control) / experiment
    ok, found = True, {}
    data = control.experiment_scenario(base, experiment)
    own = frozenset(s for s in steps if own_open_loop(s, data))
    with tempfile.TemporaryDirectory() as tmp:     # checked before --out is touched
        exp_path = write_text(dump_toml(data), Path(tmp) / f"{experiment}.toml")
        scenarios = step_scenarios(base, steps, experiment, str(opts.base))
        flag = (f"--full = {str(opts.full)!r}" if opts.full
                else f"--control = {str(opts.control)!r}")
        full = None if opts.without_full else full_configuration(
            Path(opts.full or opts.control) / experiment, exp_path, laws, seeds, flag)
        open_runs = evaluation_spec(exp_path, [BASELINE], seeds).runs()
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        baseline = open_loop_runs(control_runs, open_runs,
                                  out / step_name("control-open", experiment))
        for s in steps:
            name = step_name(s, experiment)
            path = write_text(dump_toml(scenarios[s]), out / "steps" / f"{name}.toml")
            runs, finished = recorded_evaluation(
                opts.runs, path, [BASELINE, *laws] if s in own else laws, out / name,
                baseline_from=None if s in own else baseline)
            ok &= finished
            if not runs.empty:
                found[s] = runs
        text = table(found, full, seeds, laws, own)
        md = write_text(text, out / f"{step_name('ablation', experiment)}.md")
        if opts.docs is not None:
            publish(opts.docs, opts.page, step_name(NAME, experiment),
                    "The controllers in SUMO",
                    f"Ablation of the {experiment} experiment on seeds "
                    f"{seed_text(seeds)}: each step minus the full configuration and "
                    f"minus the open loop, paired by seed (`arzsumo study {NAME}`).\n\n"
                    f"{text}", [(md, md.name)])
    return AblationResult(text, ok)


__all__ = [
    "DEAD_BAND_KMH",
    "DEFAULT_STEPS",
    "JOIN",
    "MEASURED_DEAD_TIME_S",
    "NAME",
    "PAPER_ETA",
    "POWER_LAW_STEPS",
    "PREDICTION_S",
    "QUARTER",
    "REALISED_SPEED_GAIN",
    "SPEED_LIMIT",
    "STEPS",
    "WAVE_SPEED_KMH",
    "AblationOptions",
    "apply_step",
    "default_steps",
    "describe",
    "full_configuration",
    "is_step",
    "own_open_loop",
    "run_ablation",
    "step_name",
    "step_scenario",
    "table",
]
