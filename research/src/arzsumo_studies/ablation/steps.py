"""The steps of the ablation (:mod:`arzsumo_studies.ablation.study`): what each switches on,
the scenario it evaluates, and whose open loop it borrows.

The steps start from the former default scenario (lateral_files) without its controller
side and meter realisation (:func:`base_scenario`) and switch that side on again one
change after the other (cumulative, :func:`chain`); :func:`step_scenario` gives a step's
scenario tables.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from arzsumo.sweep.evaluate import BASELINE, OPEN_LOOP_INERT, PLACEMENT_ONLY, inert_for
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    StudyError,
    fixed_cycle,
    scenario_data,
    shipped_scenario,
)

#: prediction horizon of the ``delay`` step, s: the measured dead time from a new plan to
#: the section's outflow (10-14 s) plus the mean wait for the next cycle (meter-dynamics)
PREDICTION_S = 14.0
#: the step every other one builds on, and whose open loop they may borrow
IDENTIFIED = "identified"


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
