"""Identify the macroscopic model from open-loop SUMO runs (``arzsumo identify``).

Plan every (operating point, seed) run of the open loop (``--vary table.key=v1,v2``: the
scenario with that key changed; the product of several), simulate them through the sweep
engine (each a :class:`~arzsumo.identify.ReplayData`, taken from the run cache where it
can), fit on the training runs (:func:`arzsumo.identify.identify`, after stage 1 with
``--diagram``) and score the fit on the training and the held-out runs. The steps:
``docs/identify.md``, 'What it does'. Nothing is written here: :mod:`.report` makes the
files' content.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from arzsumo.bridge.replay_data import replay_data_of, replay_options_of
from arzsumo.bridge.road import with_network
from arzsumo.bridge.session import run_in_sumo
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.identify import (
    DEFAULT_BOUNDS,
    WHICH_BY_FAMILY,
    FitSettings,
    IdentificationResult,
    ReplayData,
    ReplayOptions,
    identify,
)
from arzsumo.identify.replay import INLETS
from arzsumo.identify.wave_target import WaveTarget
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import FAMILIES, ModelParameters
from arzsumo.scenario import Scenario, scenario_from_dict
from arzsumo.sweep.driver import default_workers, map_runs
from arzsumo.workflows.identify.cache import load_run, run_key, save_run
from arzsumo.workflows.identify.diagram import STAGE_TWO, StageOne, fit_stage_one, read_waves
from arzsumo.workflows.identify.references import held_out_references
from arzsumo.workflows.identify.scores import (
    SetScore,
    ao_floor,
    score_set,
    start_params,
)

log = logging.getLogger(__name__)
ROLES = ("training", "validation")
#: the least jam occupancy stage 1 may fit: above every cell the replay is fed, or above
#: every stationary block only (``docs/identify.md``, 'Two stages')
JAM_FLOORS = ("cells", "blocks")


@dataclass(frozen=True)
class Point:
    """An operating point: scenario keys changed (``table.key`` -> value, file units)."""

    changes: tuple[tuple[str, Any], ...] = ()

    @property
    def label(self) -> str:
        """``table.key=value`` pairs, or ``scenario`` for the scenario as it is."""
        return ", ".join(f"{k}={v}" for k, v in self.changes) or "scenario"


@dataclass(frozen=True)
class RunTask:
    """One open-loop SUMO run: the scenario's tables at its point, seed and role."""

    run_id: str
    role: str
    seed: int
    point: Point
    tables: dict[str, Any]
    source: str


@dataclass(frozen=True)
class SumoRun:
    """What one run returns: its identification data and how it went."""

    task: RunTask
    data: ReplayData
    wall_time: float
    resyncs: int
    delivered: float


@dataclass(frozen=True)
class IdentifySetup:
    """A checked identification: the scenario, the runs and the fit's settings.

    ``base`` is the scenario as given; ``scenario`` the one the runs use (controller
    ``open``, horizon and warm-up overridden where asked).
    """

    base: Scenario
    scenario: Scenario
    train_seeds: tuple[int, ...]
    validate_seeds: tuple[int, ...]
    points: tuple[Point, ...]
    which: tuple[str, ...]
    fit: FitSettings
    workers: int
    #: the measured upstream wave speed lambda_4 is fitted to (m/s, < 0), and its weight
    #: (:mod:`arzsumo.identify.wave_target`); None: the replay residual alone
    wave_speed: float | None = None
    wave_weight: float = 1.0
    #: the family whose diagram stage 1 fits from the windows' stationary states (stage 2
    #: then fits tau_h, tau_a by the replay); None: one replay fit of ``which``
    diagram: str | None = None
    #: the replay's inlet flux (:data:`arzsumo.identify.replay.INLETS`)
    inlet: str = "ctm"
    #: the least jam occupancy stage 1 may fit (:data:`JAM_FLOORS`)
    jam_floor: str = "cells"

    @property
    def options(self) -> ReplayOptions:
        """The replay twin's numerics: the bridge's (``[run]`` twin_cells, twin_scheme),
        with the setup's inlet."""
        return replay_options_of(self.scenario.run, inlet=self.inlet)


def _value(text: str) -> Any:
    """A ``--vary`` value as TOML would read it: integer, number, boolean or string."""
    for kind in (int, float):
        with contextlib.suppress(ValueError):
            return kind(text)
    return {"true": True, "false": False}.get(text, text)


def parse_vary(specs: Sequence[str], sc: Scenario) -> tuple[Point, ...]:
    """Operating points of ``--vary table.key=v1,v2`` options (their product), each
    checked by applying it to ``sc``; one-line errors naming the option."""
    axes = []
    for spec in specs:
        key, sep, values = spec.partition("=")
        vals = [v.strip() for v in values.split(",") if v.strip()]
        if not sep or "." not in key or not vals:
            raise ScenarioError(f"--vary = {spec} is not allowed: table.key=v1,v2,... "
                                "(a scenario key and its values in the file's units)")
        key = key.strip()
        if key in ("sumo.seed", "run.controller"):
            raise ScenarioError(f"--vary = {spec} is not allowed: seeds come from "
                                "--train-seeds/--validate-seeds and the controller is open")
        axes.append([(key, _value(v)) for v in vals])
    points = tuple(Point(tuple(combo)) for combo in itertools.product(*axes))
    for point in points:
        try:
            sc.with_(dict(point.changes))
        except ScenarioError as exc:
            raise ScenarioError(f"--vary {point.label}: {exc}") from None
    return points


def parse_which(text: str | None, params: ModelParameters) -> tuple[str, ...]:
    """``--which`` names (comma-separated), checked against DEFAULT_BOUNDS and the names
    the model's family reads; the family's default selection without it."""
    if text is None:
        return WHICH_BY_FAMILY[params.family]
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    bad = [n for n in names if n not in DEFAULT_BOUNDS or n in params.ignored_fields]
    if not names or bad or len(set(names)) != len(names):
        allowed = [n for n in DEFAULT_BOUNDS if n not in params.ignored_fields]
        raise ScenarioError(f"--which = {text} is not allowed: distinct names from "
                            f"{', '.join(allowed)} (family = {params.family!r})")
    return names


def check_seeds(train: Sequence[int], held_out: Sequence[int]) -> None:
    """Distinct training seeds, distinct validation seeds, none in both."""
    for flag, seeds in (("--train-seeds", train), ("--validate-seeds", held_out)):
        if not seeds or len(set(seeds)) != len(seeds):
            raise ScenarioError(f"{flag} = {','.join(map(str, seeds))} is not allowed: one "
                                "or more distinct seeds")
    if both := sorted(set(train) & set(held_out)):
        raise ScenarioError(f"--validate-seeds = {','.join(map(str, held_out))} is not "
                            f"allowed: seeds {both} are also training seeds; allowed: "
                            "held-out seeds not in --train-seeds")


def make_setup(sc: Scenario, train: Sequence[int], held_out: Sequence[int], *,
               vary: Sequence[str] = (), which: str | None = None,
               horizon: float | None = None, warmup: float | None = None,
               fit: FitSettings | None = None, workers: int | None = None,
               wave_speed: float | None = None, wave_weight: float = 1.0,
               diagram: str | None = None, inlet: str = "ctm",
               jam_floor: str = "cells") -> IdentifySetup:
    """Check everything before SUMO starts: seeds, points, parameter names and bounds."""
    if inlet not in INLETS:
        raise ScenarioError(f"--inlet = {inlet} is not allowed: one of {', '.join(INLETS)}")
    if jam_floor not in JAM_FLOORS:
        raise ScenarioError(f"--jam-floor = {jam_floor} is not allowed: one of "
                            f"{', '.join(JAM_FLOORS)}")
    if diagram is not None and diagram not in FAMILIES:
        raise ScenarioError(f"--diagram = {diagram} is not allowed: one of "
                            f"{', '.join(FAMILIES)}")
    if diagram is None and jam_floor != "cells":
        raise ScenarioError(f"--jam-floor = {jam_floor} is not allowed without --diagram: "
                            "it bounds stage 1's jam occupancy; allowed: --diagram FAMILY")
    if diagram is not None and which is not None:
        raise ScenarioError(f"--which = {which} is not allowed with --diagram: stage 2 "
                            f"fits {', '.join(STAGE_TWO)}")
    check_seeds(train, held_out)
    given = {"sumo.horizon_s": horizon, "run.warmup_s": warmup}
    changes = {"run.controller": "open", **{k: v for k, v in given.items() if v is not None}}
    # a [network] table: checked with sumolib, L and W of the fit read from the network
    base, sc = sc, with_network(sc.with_(changes))
    names = STAGE_TWO if diagram is not None else parse_which(which, sc.params)
    for name in names:
        low, high = DEFAULT_BOUNDS[name]
        value = getattr(sc.params, name)
        if not low <= value <= high:
            raise ScenarioError(f"{sc.source}: [model] {name} = {value:g} (SI) is outside "
                                f"the bounds [{low:g}, {high:g}] of the fit; allowed: a start "
                                "value within them")
    points = parse_vary(vary, sc) or (Point(),)
    if wave_speed is not None:    # checked here, before SUMO starts
        WaveTarget(wave_speed, 0.0, 0.0, wave_weight)
    return IdentifySetup(base, sc, tuple(train), tuple(held_out), points, names,
                         fit or FitSettings(), workers or default_workers(), wave_speed,
                         wave_weight, diagram, inlet, jam_floor)


def plan(setup: IdentifySetup) -> list[RunTask]:
    """Every (point, seed) run, training runs first."""
    tasks = []
    for role, seeds in zip(ROLES, (setup.train_seeds, setup.validate_seeds), strict=True):
        for i, point in enumerate(setup.points):
            sc = setup.scenario.with_(dict(point.changes))
            for seed in seeds:
                rid = f"seed{seed}" if len(setup.points) == 1 else f"p{i}-seed{seed}"
                tasks.append(RunTask(rid, role, seed, point, dict(sc.tables), sc.source))
    return tasks


def simulate(task: RunTask) -> SumoRun:
    """One open-loop SUMO run as identification data (the sweep engine's worker); taken
    from the run cache (:mod:`.cache`) when the same run was made before."""
    key = run_key(task.tables, task.seed)
    if (cached := load_run(key, task.run_id)) is not None:
        data, info = cached
        return SumoRun(task, data, float(info["wall_time"]), int(info["resyncs"]),
                       float(info["delivered"]))
    start = time.perf_counter()
    res = run_in_sumo(scenario_from_dict(task.tables, task.source), seed=task.seed).result
    data = replay_data_of(res, name=task.run_id)
    delivered = res.report.delivered_main if res.report is not None else math.nan
    run = SumoRun(task, data, time.perf_counter() - start,
                  int(res.twin_status["replay"]["resyncs"]), float(delivered))
    save_run(key, data, {"wall_time": run.wall_time, "resyncs": run.resyncs,
                         "delivered": run.delivered})
    return run


@dataclass(frozen=True)
class IdentifyStudy:
    """Everything an identification produced (SI).

    ``measured`` is the mean (rho_h, rho_a) of the training runs' cells and periods, veh/m;
    ``equilibrium`` the identified model's equilibrium there (None where the identified
    model cannot hold it: AO >= AO_max); ``wall`` the wall times, s (``wall_time`` in
    ``docs/outputs.md``).
    """

    setup: IdentifySetup
    runs: tuple[SumoRun, ...]
    fit: IdentificationResult
    start: SetScore
    training: SetScore
    validation: SetScore
    measured: tuple[float, float]
    equilibrium: Equilibrium | None
    wall: dict[str, float]
    #: stage 1 (``--diagram``) and the scenario's own model scored on the held-out runs
    stage_one: StageOne | None = None
    scenario_validation: SetScore | None = None
    #: the held-out runs' block errors of the references (:mod:`.references`)
    references: dict[str, Any] | None = None

    def data(self, role: str) -> list[ReplayData]:
        """The ReplayData of the ``training`` or ``validation`` runs."""
        return [r.data for r in self.runs if r.task.role == role]


def measured_densities(datasets: Sequence[ReplayData]) -> tuple[float, float]:
    """Mean (rho_h, rho_a) over the runs' observed cells and periods, veh/m."""
    rho_h = np.concatenate([d.fields[:, 0].ravel() for d in datasets])
    rho_a = np.concatenate([d.fields[:, 2].ravel() for d in datasets])
    return float(np.nanmean(rho_h)), float(np.nanmean(rho_a))


def equilibrium_at(params: ModelParameters, rho: tuple[float, float]) -> Equilibrium | None:
    """The equilibrium of ``params`` at densities ``rho`` (veh/m), or None outside it."""
    try:
        return Equilibrium(params, *rho)
    except ArzsumoError:
        return None


def run_identification(setup: IdentifySetup) -> IdentifyStudy:
    """Plan, simulate, fit and validate (module docstring)."""
    t0 = time.perf_counter()
    tasks = plan(setup)
    here = setup.workers <= 1 or len(tasks) <= 1
    runs = tuple(map_runs(simulate, tasks, workers=setup.workers, in_process=here))
    t1 = time.perf_counter()
    train = [r.data for r in runs if r.task.role == "training"]
    held_out = [r.data for r in runs if r.task.role == "validation"]
    opts = setup.options
    rho = measured_densities(train)
    stage_one, t_one = None, time.perf_counter()
    if setup.diagram is not None:
        # cells: the jam occupancy above every cell the replay is fed (at its AO limit);
        # blocks: above every stationary block only (fit_stage_one's own floor)
        floor = (ao_floor(setup.scenario.params, train, opts.ao_limit)
                 if setup.jam_floor == "cells" else None)
        diagram, reading, states = fit_stage_one(
            setup.scenario, setup.diagram, train, rho, wave=setup.wave_speed,
            wave_weight=setup.wave_weight, bootstrap=setup.fit.bootstrap, floor=floor)
        stage_one = StageOne(diagram, states, {"training": reading,
                                               "validation": read_waves(held_out)})
        guess = diagram.params
        t_one = time.perf_counter() - t_one
    else:
        t_one = 0.0
        guess = start_params(setup.scenario.params, train, opts.ao_limit)
    if guess.ao_max_h != setup.scenario.params.ao_max_h:
        log.info("fit starts from AO_max_h = %.3f, AO_max_a = %.3f", guess.ao_max_h,
                 guess.ao_max_a)
    start = score_set(guess, train, opts)
    t2 = time.perf_counter()
    floor = ao_floor(guess, train, opts.ao_limit)
    bounds = {name: (floor, 1.0) if name.startswith("ao_max") else DEFAULT_BOUNDS[name]
              for name in setup.which}
    target = (WaveTarget(setup.wave_speed, *rho, setup.wave_weight)
              if setup.wave_speed is not None and stage_one is None else None)
    fit = identify(train, guess, bounds, which=setup.which, options=opts,
                   settings=setup.fit, wave_target=target)
    t3 = time.perf_counter()
    training = score_set(fit.params, train, opts)
    validation = score_set(fit.params, held_out, opts)
    t4 = time.perf_counter()
    wall = {"sumo": t1 - t0, "sumo_runs": float(sum(r.wall_time for r in runs)),
            "fit": fit.wall_time, "bootstrap": t3 - t2 - fit.wall_time,
            "stage_one": t_one, "validate": (t4 - t3) + (t2 - t1) - t_one, "total": t4 - t0}
    own = score_set(setup.scenario.params, held_out, opts)
    return IdentifyStudy(setup, runs, fit, start, training, validation, rho,
                         equilibrium_at(fit.params, rho), wall, stage_one, own,
                         held_out_references(fit.params, train, held_out, validation, own))
