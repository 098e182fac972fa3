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
                    (:func:`arzsumo.model.wave_match.wave_matched`)
dead-band           the ETC's trigger with the noise dead band :data:`DEAD_BAND_KMH`
                    (``[design] noise_sd_kmh``; backstepping does not read it)
power-law           the laws (and twins) on the shipped default's power-law model,
                    equilibrium and ``[design]`` (:func:`_power_law`)
paper-trigger       the ETC's trigger as in the paper: no dead band measured on the
                    estimate (``[design] noise_from_estimate`` off)
unit-gain           the laws on the paper's unit actuator: ``[actuation] meter_gain`` 1
quarter-law         the laws' command to the meter :data:`QUARTER` times smaller
                    (``[actuation] meter_gain`` times :data:`QUARTER`): their swings
                    inside the meter's range (:func:`_quarter_law`)
==================  ==============================================================

The steps change the regulation experiment, or with ``--experiment disturbance`` the
disturbance experiment (then against the control study's disturbance runs). Each step is
an evaluation (:func:`~arzsumo.sweep.evaluate.run_evaluation`) into ``OUT/<step>/``
(``OUT/<step>-disturbance/``). A step that does not act on an open loop borrows the open
loop of the control study (``--control DIR``: its ``--out``, or its record store, whose
open-loop records are then restored into ``OUT/control-open/``); ``fixed-cycle`` changes
the plant and runs its own. The table gives each step minus the full configuration and
minus the open loop.
"""

from __future__ import annotations

import tempfile
import tomllib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from arzsumo.errors import ArzsumoError
from arzsumo.evaluation.report import Measure, paired_cell, seed_values
from arzsumo.io import dump_toml, read_toml
from arzsumo.model.wave_match import wave_matched
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import publish, write_text
from arzsumo.resources import default_scenario
from arzsumo.scenario import scenario_from_dict
from arzsumo.studies import checks
from arzsumo.studies.common import RESULTS_DIR, StudyError, seed_text
from arzsumo.studies.control import study as control
from arzsumo.studies.recorded import RecordedRuns, recorded_evaluation
from arzsumo.sweep.evaluate import BASELINE, evaluation_spec
from arzsumo.sweep.evaluate import KIND as EVALUATION_KIND
from arzsumo.sweep.records import copy_records, is_store, records_table
from arzsumo.sweep.spec import RunSpec
from arzsumo.sweep.worker import FINISHED
from arzsumo.units import kmh_to_ms

NAME = "control-ablation"
#: the results page this study keeps a block of (the control study's)
PAGE = control.PAGE
#: the laws ablated
LAWS = ("backstepping", "etc")
#: prediction horizon of ``predictor``, s: the dead time from a new plan to the section's
#: outflow measured on the meter (10-14 s, arzsumo study meter-dynamics)
PREDICTION_S = 14.0
#: prediction horizon of ``predictor-measured``, s: the dead time from the held meter's
#: command to the section's outflow at x = L on the default, 26-27 s on regulation seeds
#: 11-16 and 26-30 s on disturbance seeds 11-14 (arzsumo study meter-delay)
MEASURED_DEAD_TIME_S = 27.0


def _set(changes: dict[str, object]) -> Callable[[dict], dict]:
    def apply(data: dict) -> dict:
        for dotted, value in changes.items():
            table, _, key = dotted.partition(".")
            data.setdefault(table, {})[key] = value
        return data
    return apply


#: SUMO's upstream wave speed on the default, km/h: the HV fluctuations' speed that
#: ``arzsumo premise`` measured on seeds 6-8, -35 to -39 km/h
#: (docs/results/premise_coupled.md); the identified model has lambda_4 = -2.55 km/h
WAVE_SPEED_KMH = -35.0


def _wave_matched(data: dict) -> dict:
    """``data`` with the ``[model]`` of :func:`~arzsumo.model.wave_match.wave_matched`:
    lambda_4 at the scenario's equilibrium moved to :data:`WAVE_SPEED_KMH`.

    The four values are written with every digit of the root finder's answer, so the
    step's fingerprint (and its records) hold for as long as numpy and scipy give the
    same root to the last bit; another answer makes the records stale, and they run
    again."""
    sc = scenario_from_dict(data)
    eq = sc.equilibrium
    q = wave_matched(sc.params, eq.rho_h, eq.rho_a, float(kmh_to_ms(WAVE_SPEED_KMH)))
    data.setdefault("model", {}).update(
        {k: float(getattr(q, k)) for k in ("gamma_h", "gamma_a", "ao_max_h", "ao_max_a")})
    return data


#: the ETC trigger's noise dead band of ``dead-band`` (``[design] noise_sd_kmh``, km/h, one
#: sd per scaled Riemann variable w_1..w_4): twice the w-bar noise that 1 % relative state
#: noise puts on the laws' grid, the band that brought the twin's ETC to 0.29 of its
#: checks at SUMO's noise level (2 %; docs/readings/etc_remedies.md)
DEAD_BAND_KMH = (5.569, 0.3392, 0.8406, 0.256)

def _band_by_hand(data: dict) -> dict:
    """``data`` with :data:`DEAD_BAND_KMH` as the ETC's dead band, in place of one measured
    on the estimate (the two cannot be combined)."""
    data = _set({"design.noise_sd_kmh": list(DEAD_BAND_KMH), "design.noise_k": 2.0})(data)
    data["design"].pop("noise_from_estimate", None)
    return data


def _power_law(data: dict) -> dict:
    """``data`` with the shipped default's ``[model]`` (the paper's power-law diagram,
    identified on the Krauss stream), the trigger's measured dead band kept where
    ``data`` asks for it.

    Where the equilibrium places the open loop (``[run] start = "placement"``: the
    section placed at the ``[equilibrium]`` densities) the equilibrium stays, so that the
    step does not move the plant, and ``[design]`` is chosen for the power law there as
    ``arzsumo design-check --auto`` chooses it (:func:`_designed`). Elsewhere the
    default's ``[equilibrium]`` and ``[design]`` come with its model."""
    default = tomllib.loads(default_scenario().read_text(encoding="utf-8"))
    measured = data.get("design", {}).get("noise_from_estimate")
    placed = data.get("run", {}).get("start") == "placement"
    for table in ("model",) if placed else ("model", "equilibrium", "design"):
        data[table] = dict(default[table])
    if placed:
        data["design"] = _designed(data)
    if measured is not None:
        data["design"]["noise_from_estimate"] = measured
    return data


def _designed(data: dict) -> dict:
    """The ``[design]`` table that ``design-check --auto`` chooses for the scenario
    ``data`` on its ``[run] kernel_cells`` (about 3 s the first time; the kernels are
    cached), to the digits ``design-check`` prints: the same table as long as the
    kernels give the same design to six digits, and with it the step's records."""
    from arzsumo.control.design import design_for
    from arzsumo.kernel_cache import cached_kernels
    from arzsumo.model import linearize
    from arzsumo.scenario.model import design_toml

    sc = scenario_from_dict(data)
    lin = linearize(sc.equilibrium)
    choice = design_for(lin.system, cached_kernels(lin.system, sc.run.kernel_cells),
                        base=sc.design)
    return tomllib.loads(design_toml(choice.design, "power-law step"))["design"]


#: how much smaller ``quarter-law`` makes the laws' command to the meter. On the IDM
#: stream backstepping asked for an outflow U with sd 430-620 veh/h, 660-950 veh/h of
#: ramp release at its meter gain 0.65, against a meter whose release spans 660 veh/h
#: (240-900): saturated 48-70 % of the time (docs/readings/control_idm.md). A quarter of
#: it, sd 165-240 veh/h of release, mostly lies inside that span.
QUARTER = 4.0


def _quarter_law(data: dict) -> dict:
    """``data`` with ``[actuation] meter_gain`` :data:`QUARTER` times larger: the laws
    ask the meter for U / (gain x QUARTER) and are told that what reached the boundary
    was gain x QUARTER times the release applied, so their anti-windup sees an
    unsaturated U where the meter was not saturated. The law's loop gain is a quarter
    of its design's: a detuned law that the meter can carry out, not the paper's."""
    act = data.setdefault("actuation", {})
    act["meter_gain"] = float(act.get("meter_gain", 1.0)) * QUARTER
    return data


#: step -> (what it changes, the change on the scenario as written, acts on the open loop)
STEPS: dict[str, tuple[str, Callable[[dict], dict], bool]] = {
    "raw-cells": ("the laws on SUMO's Edie cells (no estimator)",
                  _set({"estimation.method": "none"}), False),
    "equilibrium": ("deviations from the model's equilibrium",
                    _set({"estimation.reference": "equilibrium"}), False),
    "no-saturation": ("no bounds on U, no ramp bound, no anti-windup",
                      _set({"actuation.u_max_fraction": 0.0,
                            "actuation.u_rate_max_veh_h_s": 0.0,
                            "actuation.ramp_bound": False, "actuation.anti_windup": False}),
                      False),
    "fixed-cycle": ("the meter as a fixed cycle of green shares",
                    _set({"sumo.meter_mode": "fixed_cycle"}), True),
    "predictor": (f"the laws on the state predicted {PREDICTION_S:g} s ahead",
                  _set({"actuation.delay_compensation_s": PREDICTION_S}), False),
    "predictor-measured": (f"the laws on the state predicted {MEASURED_DEAD_TIME_S:g} s "
                           "ahead, the meter's dead time measured on the default",
                           _set({"actuation.delay_compensation_s": MEASURED_DEAD_TIME_S}),
                           False),
    "wave-matched": (f"the model's lambda_4 at SUMO's wave speed, {WAVE_SPEED_KMH:g} km/h",
                     _wave_matched, False),
    "dead-band": ("the ETC's trigger with a dead band sized to the estimate's noise",
                  _band_by_hand, False),
    "power-law": ("the laws on the default's power-law model and design", _power_law,
                  False),
    "paper-trigger": ("the ETC's trigger as in the paper (no measured dead band)",
                      _set({"design.noise_from_estimate": False}), False),
    "unit-gain": ("the laws on the paper's unit actuator (meter_gain 1)",
                  _set({"actuation.meter_gain": 1.0}), False),
    "quarter-law": (f"the laws' command to the meter {QUARTER:g} times smaller, inside "
                    "its range", _quarter_law, False),
}
#: the steps run unless ``--steps`` names others: those of the default's configuration
#: (``power-law``, ``paper-trigger`` and ``unit-gain`` change nothing on the default, whose
#: model is the power law, whose trigger is the paper's and whose meter gain is 1;
#: ``quarter-law`` is for a stream where the laws saturate the meter)
DEFAULT_STEPS = tuple(s for s in STEPS if s not in ("power-law", "paper-trigger",
                                                    "unit-gain", "quarter-law"))
#: the measures of the ablation table (keys of the control study's measures)
KEYS = ("network_whole_demand.time_spent_s.total", "network_whole_demand.ramp_wait_s.p95",
        "section.deviation.deviation_excess_s", "section.deviation.decay_time_s",
        "section.waves.h.band_power_kmh2", "section.waves.a.band_power_kmh2",
        "section.speed_oscillation_kmh.h", "section.speed_oscillation_kmh.a",
        "section.waves.h.growth_per_km", "plan_changes", "triggers")


def step_name(step: str, experiment: str = "regulation") -> str:
    """The name of a step's evaluation (its directory under ``--out`` and in the record
    store): the step's own in the regulation experiment, suffixed in another."""
    return step if experiment == "regulation" else f"{step}-{experiment}"


def step_scenario(base: dict, step: str, experiment: str = "regulation") -> dict:
    """The control study's ``experiment`` scenario of ``base`` with ``step``'s change."""
    data = control.experiment_scenario(base, experiment)
    data = STEPS[step][1]({k: dict(v) if isinstance(v, dict) else v
                           for k, v in data.items()})
    data["name"] = f"{base.get('name', 'scenario')}-ablation-{step_name(step, experiment)}"
    return data


def measures() -> list[Measure]:
    return [next(m for m in control.MEASURES if m.key == k) for k in KEYS]


def _cells(a_runs: pd.DataFrame, a: str, b_runs: pd.DataFrame, b: str,
           seeds: list[int]) -> list[str]:
    """Per measure, ``a`` of ``a_runs`` minus ``b`` of ``b_runs``, paired by seed:
    mean [95 % t] wins/losses of ``a`` (empty where there are too few pairs)."""
    return [paired_cell(seed_values(a_runs, m, a, seeds), seed_values(b_runs, m, b, seeds),
                        lower_is_better=m.lower_is_better) for m in measures()]


def table(steps: dict[str, pd.DataFrame], full: pd.DataFrame, seeds: list[int],
          laws: Sequence[str] = LAWS) -> str:
    """Markdown: per step, law and measure, the step minus the full configuration and the
    step minus the open loop of its evaluation, paired by seed (mean [95 % t]
    wins/losses of the step); first, the full configuration minus the open loop, where a
    step borrowed the control study's open loop."""
    lines = ["| step | law | minus | " + " | ".join(f"{m.label} ({m.unit})"
                                                  for m in measures()) + " |",
             "|---" * (3 + len(KEYS)) + "|"]
    borrowed = next((r for s, r in steps.items() if not STEPS[s][2]
                     and BASELINE in set(r["controller"])), None)
    if borrowed is not None:
        for law in laws:
            lines.append(f"| full | {law} | open | "
                         + " | ".join(_cells(full, law, borrowed, BASELINE, seeds)) + " |")
    for step, runs in steps.items():
        for law in laws:
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
    ``--out`` or record store (its runs of ``experiment`` are the full configuration);
    ``steps`` of :data:`STEPS`, ``laws`` of :data:`LAWS`; ``out``, ``docs``: where the
    study writes (None: no page); ``page``: the results page under ``docs`` that gets
    the table (the control study's page of the same scenario).
    """

    runs: RecordedRuns
    scenario: Path | None = None
    control: Path = RESULTS_DIR / control.NAME
    experiment: str = "regulation"
    steps: tuple[str, ...] = DEFAULT_STEPS
    laws: tuple[str, ...] = LAWS
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    page: str = PAGE

    def __post_init__(self) -> None:
        checks.among(self.experiment, control.EXPERIMENTS, "experiment")
        checks.all_among(self.steps, tuple(STEPS), "steps")
        checks.all_among(self.laws, LAWS, "laws")

    @property
    def base(self) -> Path:
        """The control study's base scenario file."""
        return self.scenario or default_scenario()


@dataclass(frozen=True)
class AblationResult:
    """The table (Markdown) and whether every step's runs finished."""

    text: str
    complete: bool


def design(opts: AblationOptions) -> list[str]:
    """One line per step: what it changes, the laws and seeds (``--list``)."""
    return [f"{s}: {STEPS[s][0]}; {', '.join(opts.laws)} on seeds "
            f"{seed_text(list(opts.runs.seeds))}" for s in opts.steps]


def full_configuration(runs_dir: Path, scenario: Path, laws: Sequence[str],
                       seeds: Sequence[int], user: str) -> pd.DataFrame:
    """The finished runs of ``laws`` on ``seeds`` that the control study's directory or
    store ``runs_dir`` (one experiment's) holds of ``scenario``; a StudyError if one
    lacks."""
    runs = records_table(evaluation_spec(scenario, laws, seeds).runs(), runs_dir)
    missing = runs.loc[~runs["status"].isin(FINISHED), "run_id"].tolist()
    if missing:
        raise StudyError(f"--control = {user!r} is not allowed: it has no finished "
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
    steps, laws, seeds = list(opts.steps), list(opts.laws), list(opts.runs.seeds)
    _, base = read_toml(opts.base, "scenario", StudyError)
    experiment = opts.experiment
    control_runs = Path(opts.control) / experiment
    ok, found = True, {}
    with tempfile.TemporaryDirectory() as tmp:     # checked before --out is touched
        exp_path = write_text(dump_toml(control.experiment_scenario(base, experiment)),
                              Path(tmp) / f"{experiment}.toml")
        scenarios = step_scenarios(base, steps, experiment, str(opts.base))
        full = full_configuration(control_runs, exp_path, laws, seeds, str(opts.control))
        open_runs = evaluation_spec(exp_path, [BASELINE], seeds).runs()
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        baseline = open_loop_runs(control_runs, open_runs,
                                  out / step_name("control-open", experiment))
        for s in steps:
            name = step_name(s, experiment)
            path = write_text(dump_toml(scenarios[s]), out / "steps" / f"{name}.toml")
            own_open = STEPS[s][2]
            runs, finished = recorded_evaluation(
                opts.runs, path, [BASELINE, *laws] if own_open else laws, out / name,
                baseline_from=None if own_open else baseline)
            ok &= finished
            if not runs.empty:
                found[s] = runs
        text = table(found, full, seeds, laws)
        md = write_text(text, out / f"{step_name('ablation', experiment)}.md")
        if opts.docs is not None:
            publish(opts.docs, opts.page, step_name(NAME, experiment),
                    "The controllers in SUMO",
                    f"Ablation of the {experiment} experiment on seeds "
                    f"{seed_text(seeds)}: each step minus the full configuration and "
                    f"minus the open loop, paired by seed (`arzsumo study {NAME}`).\n\n"
                    f"{text}", [(md, md.name)])
    return AblationResult(text, ok)


__all__ = ["NAME", "STEPS", "AblationOptions", "full_configuration", "run_ablation",
           "step_name", "step_scenario", "table"]
