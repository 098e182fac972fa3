"""The SUMO side of ``arzsumo premise``: the open-loop runs the premise gates measure.

Per seed three open-loop runs of the scenario that share one warm-up (``[run]
warmup_s``, the fill phase ``[sumo] fill_s`` included) under the nominal meter plan: the
warm-up runs once, and each run's window runs in a child process forked at its end
(:mod:`arzsumo.sumo.fork`; bit for bit what three separate runs give), all through the
one step loop :class:`~arzsumo.sumo.plant.SumoPlant` (the windows through its open-loop
driver, :meth:`~arzsumo.sumo.plant.SumoPlant.run_open_loop`, which reads what they keep):

* ``baseline``: the window (``window_s``) at the nominal plan. Kept: the window's mean
  class densities (veh/m) and mainline outflow q(L) (veh/s); per control period:
  the Edie speed fields per class (50 m cells), the section's vehicle count (Edie, veh),
  the vehicles on ``main`` at the period's end, and a lateral snapshot of every vehicle on
  ``main`` (:class:`~arzsumo.sumo.lateral.LateralSampler` on the mainline sensor's sample
  of the period's last step, as the sensor takes it in a control window; reduced here to
  the coupling gates, the samples being too many to store: about 150 per period); SUMO's
  report (inserted and requested vehicles) and the meter's largest ramp queue of the
  window.
* ``pulse``: the same seed and window, the meter at its *least plan* for ``pulse_s`` from
  the window's start, then back at the nominal plan. The least plan is
  ``meter.plan_bounds[0]``: green share ``[sumo] green_share_min`` for the fixed cycle (0:
  red for the whole pulse) and ``[sumo] release_rate_min_veh_h`` for one vehicle per green
  (its nearest to red: it has no red plan). The queue override still acts. Kept: the
  speed fields.
* ``staircase``: the release rate stepped by +-``step`` (veh/s) around the nominal,
  ``levels`` levels of ``level_s`` after a nominal lead-in of ``level_s``, in the order
  +, 0, -, 0, +, 0, ... (two steps up and two down every four levels). The plan of a
  rate r = r_nominal + dr is :func:`plan_for_step`: the rate itself for one vehicle per
  green (``meter.set_plan(r)``); for the fixed cycle the green share whose meter-curve
  outflow is q* - dr (the command U = -dr, as :func:`arzsumo.bridge.actuator.command_meter`
  maps it). Kept per period: the section's outflow q(L) (the sensor's outflow_h +
  outflow_a), the commanded r, and the ramp vehicles released (the meter's count).

:func:`premise_runs` lays out one :class:`~arzsumo_studies.design.StudyRun` per (seed,
kind) for :func:`~arzsumo_studies.design.run_design` (the sweep engine's local pool or
Dask); :func:`run_premise_task` is its worker. SI units: s, m, m/s, veh, veh/s.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from arzsumo.errors import ArzsumoError
from arzsumo.scenario import Scenario
from arzsumo.sumo.config import SumoConfig, ramp_capacity
from arzsumo.sumo.fork import BranchFailed
from arzsumo.sumo.green_share import GreenShareCurve
from arzsumo.units import VEH_H_PER_VEH_S, veh_s_to_veh_h
from arzsumo_studies.common import study_spec
from arzsumo_studies.design import StudyRun, design_runs

if TYPE_CHECKING:
    from arzsumo.sumo.plant import SumoPlant

log = logging.getLogger(__name__)

NAME = "premise"
#: the runs of one seed, in the order they are laid out
KINDS = ("baseline", "pulse", "staircase")
#: the staircase's levels in units of the step: +, 0, -, 0, repeated
PATTERN = (1, 0, -1, 0)
CLASSES = ("hv", "av")


class PremiseRunError(ArzsumoError, ValueError):
    """Premise runs that cannot be made as asked (durations, steps outside the meter)."""


@dataclass(frozen=True)
class PremiseOptions:
    """The durations and steps of the premise runs (SI: s, veh/s).

    ``window``: baseline and pulse window after the warm-up; ``pulse``: the least plan's
    hold; ``level``: each staircase level (and the lead-in); ``levels``: staircase levels
    after the lead-in; ``step``: the release-rate step.
    """

    window: float
    pulse: float = 25.0
    level: float = 120.0
    levels: int = 8
    step: float = 200.0 / VEH_H_PER_VEH_S

    def for_kind(self, kind: str) -> dict[str, Any]:
        """The options one kind of run depends on (its row is reused while they hold)."""
        if kind == "baseline":
            return {"kind": kind, "window_s": self.window}
        if kind == "pulse":
            return {"kind": kind, "window_s": self.window, "pulse_s": self.pulse}
        return {"kind": kind, "level_s": self.level, "levels": self.levels,
                "step_veh_s": self.step}

    def as_dict(self) -> dict[str, float | int]:
        """The options with units in their names (s, veh/h)."""
        return {"window_s": self.window, "pulse_s": self.pulse, "level_s": self.level,
                "levels": self.levels, "step_veh_h": veh_s_to_veh_h(self.step)}


# -- the meter's plans (pure: no SUMO) -----------------------------------------------------
def nominal_plan(cfg: SumoConfig) -> float:
    """The open loop's plan: ``release_rate`` (veh/s, one per green) or ``green_share``."""
    return cfg.release_rate if cfg.meter_mode == "one_per_green" else cfg.green_share


def least_plan(cfg: SumoConfig) -> float:
    """The pulse's plan, the meter's ``plan_bounds[0]``: ``release_rate_min`` (veh/s) or
    ``green_share_min``."""
    return cfg.release_rate_min if cfg.meter_mode == "one_per_green" else cfg.green_share_min


def plan_for_step(cfg: SumoConfig, curve: GreenShareCurve, dr: float) -> float:
    """The plan of release rate r_nominal + ``dr`` (veh/s): that rate (one per green), or
    the green share whose outflow on ``curve`` is q* - dr (fixed cycle; q* the curve's
    outflow at ``green_share``). Refused when the meter cannot run it."""
    if dr == 0:
        return nominal_plan(cfg)
    if cfg.meter_mode == "one_per_green":
        plan, lo, hi = cfg.release_rate + dr, cfg.release_rate_min, cfg.release_rate_max
        if not lo <= plan <= hi:
            step, rate, low, high = (veh_s_to_veh_h(v) for v in (abs(dr), cfg.release_rate,
                                                                 lo, hi))
            raise PremiseRunError(
                f"--step-veh-h = {step:g} is not allowed: the release rate "
                f"{rate:g} {'+' if dr > 0 else '-'} {step:g} "
                f"veh/h lies outside the meter's [{low:g}, {high:g}] veh/h "
                "([sumo] release_rate_min_veh_h, release_rate_max_veh_h)")
        return plan
    m = curve.monotone()
    q = m.outflow_at(cfg.green_share) - dr
    plan = m.green_share_for(q)
    if not (min(m.outflow) <= q <= max(m.outflow)
            and cfg.green_share_min <= plan <= cfg.green_share_max):
        step, to, low, high = (veh_s_to_veh_h(v) for v in (abs(dr), q, min(m.outflow),
                                                           max(m.outflow)))
        raise PremiseRunError(
            f"--step-veh-h = {step:g} is not allowed: the fixed-cycle meter "
            f"cannot move the mainline outflow to {to:.0f} veh/h within its meter "
            f"curve ({low:.0f}-{high:.0f} veh/h) and "
            f"[sumo] green_share_min .. green_share_max")
    return plan


def staircase_levels(levels: int) -> list[int]:
    """The staircase in units of the step, lead-in first: 0, +1, 0, -1, 0, +1, ..."""
    return [0] + [PATTERN[k % len(PATTERN)] for k in range(levels)]


def check_options(sc: Scenario, opts: PremiseOptions, curve: GreenShareCurve) -> None:
    """Refuse options the runs cannot realise, before any SUMO run (one line each)."""
    period = sc.sumo.control_period
    for flag, value in (("--window", opts.window), ("--pulse-s", opts.pulse),
                        ("--level-s", opts.level)):
        k = value / period
        if abs(k - round(k)) > 1e-9 or round(k) < 2:
            raise PremiseRunError(f"{flag} = {value:g} is not allowed: a whole number of "
                                  f"control periods, at least 2 ({sc.source}: [sumo] "
                                  f"control_period_s = {period:g})")
    if opts.pulse >= opts.window:
        raise PremiseRunError(f"--pulse-s = {opts.pulse:g} is not allowed: shorter than "
                              f"the window (--window = {opts.window:g} s)")
    if opts.levels < 2:
        raise PremiseRunError(f"--levels = {opts.levels} is not allowed: at least 2 (a step "
                              "up and a step down)")
    for dr in (opts.step, -opts.step):
        plan_for_step(sc.sumo, curve, dr)


# -- the design ----------------------------------------------------------------------------
def horizon_periods(opts: PremiseOptions, run: StudyRun) -> int:
    """Control periods after the warm-up that every kind's SUMO run of ``run``'s scenario
    is set up for (the longest kind's): the runs of a seed then share everything up to
    the warm-up's end."""
    from arzsumo.scenario import scenario_from_dict

    period = scenario_from_dict(run.scenario, run.source).sumo.control_period
    return max(_periods(opts.window, period),
               _periods(opts.level, period) * (opts.levels + 1))


def premise_runs(path: Path, seeds: list[int], warmup: float,
                 opts: PremiseOptions) -> list[StudyRun]:
    """One run per (seed, kind) of the scenario file ``path`` with warm-up ``warmup`` (s):
    IDs ``seed=S,kind=K``, seeds in order, kinds as :data:`KINDS`."""
    spec = study_spec(NAME, path, seeds=list(seeds), set={"run.warmup_s": float(warmup)})
    runs = design_runs(spec)
    n = horizon_periods(opts, runs[0])
    return [replace(r, run_id=f"{r.run_id},kind={kind}",
                    options={**opts.for_kind(kind), "horizon_periods": n})
            for r in runs for kind in KINDS]


def grouped(runs: Sequence[StudyRun]) -> list[StudyRun]:
    """The runs that share a scenario (and so their warm-up) as one run each: ID
    ``seed=S`` (the runs' IDs up to ``,kind=``), options ``{"group": [[ID, options],
    ...]}``, for :func:`run_premise_group`."""
    groups: dict[str, list[StudyRun]] = {}
    for r in runs:
        groups.setdefault(r.run_id.split(",kind=")[0], []).append(r)
    return [replace(rs[0], run_id=key, options={"group": [[r.run_id, dict(r.options)]
                                                          for r in rs]})
            for key, rs in groups.items()]


def ungrouped(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The per-kind rows of :func:`run_premise_group`'s rows."""
    return [dict(r) for g in rows for r in g["rows"]]


# -- the worker ----------------------------------------------------------------------------
def run_premise_task(run: StudyRun) -> dict[str, Any]:
    """One premise run (``run.options["kind"]``) with its own warm-up: its arrays as lists
    (JSON-able)."""
    from arzsumo.scenario import scenario_from_dict

    sc = scenario_from_dict(run.scenario, run.source)
    return _simulate(sc, [run.options], fork=False)[0]


def run_premise_group(run: StudyRun) -> dict[str, Any]:
    """The runs of one group (:func:`grouped`): one warm-up, then each run in a child
    forked at its end (:mod:`arzsumo.sumo.fork`), bit for bit what
    :func:`run_premise_task` gives; a run whose child fails runs again alone."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.sumo.fork import can_fork

    sc = scenario_from_dict(run.scenario, run.source)
    opts = [o for _, o in run.options["group"]]
    if not can_fork():     # e.g. a threaded Dask worker: one warm-up per run instead
        return {"rows": [_simulate(sc, [o], fork=False)[0] for o in opts]}
    rows = _simulate(sc, opts, fork=True)
    for i, row in enumerate(rows):
        if isinstance(row, BranchFailed):
            log.warning("%s %s: %s; running it again alone", run.run_id,
                        opts[i]["kind"], row.reason)
            rows[i] = {**_simulate(sc, [opts[i]], fork=False)[0], "rerun": True}
    return {"rows": rows}


def _periods(duration: float, period: float) -> int:
    return max(1, round(duration / period))


def placed_fields(sc: Scenario) -> np.ndarray | None:
    """The fields (4, cells) to place vehicles from at t = 0 with ``[run] start =
    "placement"`` (the ``[initial]`` profile about the scenario's equilibrium on SUMO's
    cells, as a closed-loop run places them); None otherwise."""
    from arzsumo.pde.initial import initial_fields
    from arzsumo.scenario.twin import seeded

    if sc.run.start != "placement":
        return None
    n = round(sc.params.length / sc.sumo.cell_length)
    xc = (np.arange(n) + 0.5) * sc.sumo.cell_length
    return initial_fields(seeded(sc.initial, sc.sumo.seed), sc.equilibrium, xc)


def _simulate(sc: Scenario, opts: Sequence[Mapping[str, Any]], fork: bool) -> list[Any]:
    """The warm-up, then the window of each of ``opts`` (in forked children with
    ``fork`` and more than one, else the one window in this process). The caller checks
    :func:`~arzsumo.sumo.fork.can_fork`."""
    from arzsumo.bridge.cosim import place_initial, warm_up
    from arzsumo.bridge.session import meter_curve_of
    from arzsumo.progress import Progress
    from arzsumo.sumo.fork import run_branches
    from arzsumo.sumo.plant import SumoPlant
    from arzsumo.sumo.simulation import open_simulation

    wall0 = time.perf_counter()
    period = sc.sumo.control_period
    t_w = max(1, math.ceil(sc.run.warmup / period - 1e-9)) * period
    n = max(int(o.get("horizon_periods", 0)) for o in opts)
    cfg = sc.sumo.with_(horizon=t_w + max(n, 1) * period)
    initial, _ = place_initial(sc.params, sc.run, cfg, placed_fields(sc))
    with open_simulation(sc.params, cfg, initial=initial,
                         downstream_loop=sc.alinea.loop_distance) as sim:
        plant = SumoPlant(sim, sc.params.length, cfg, meter_curve_of(cfg, sc.source))
        warm = warm_up(plant, sc.run.warmup, period, Progress(1, enabled=False))
        warm_s = time.perf_counter() - wall0
        branches = [partial(_branch, sc, plant, float(warm[-1].t), o, warm_s)
                    for o in opts]
        if fork and len(branches) > 1:
            return run_branches(branches)
        if len(branches) != 1:
            raise PremiseRunError("several premise runs without a fork; allowed: one")
        return [branches[0]()]


@dataclass
class _OpenLoop:
    """What one open-loop run kept (per period of the window, SI)."""

    t0: float
    cells: list[Any]
    main_vehicles: list[int]
    releases: list[int]
    lateral: Any
    report: Any
    meter: dict[str, Any]
    cfg: SumoConfig


def _branch(sc: Scenario, plant: SumoPlant, t0: float, opt: Mapping[str, Any],
            warm_s: float) -> dict[str, Any]:
    """One kind's window after the warm-up, and its row."""
    wall0 = time.perf_counter()
    kind, period = opt["kind"], sc.sumo.control_period
    if kind == "staircase":
        row = _staircase(sc, plant, t0, opt)
    else:
        plans: dict[int, float] = {}
        if kind == "pulse":
            plans = {0: least_plan(sc.sumo), _periods(opt["pulse_s"], period):
                     nominal_plan(sc.sumo)}
        rec = _window(plant, t0, _periods(opt["window_s"], period), plans,
                      lateral=kind == "baseline")
        row = _fields_row(rec) if kind == "pulse" else _baseline_row(sc, rec)
        if kind == "pulse":
            row["pulse_plan"] = plans[0]
    # the window's own wall time; the shared warm-up's apart (once per seed, not per kind)
    return {"kind": kind, "seed": sc.sumo.seed, **row,
            "wall_s": time.perf_counter() - wall0, "warmup_wall_s": warm_s}


def _window(plant: SumoPlant, t0: float, periods: int, plans: Mapping[int, float],
            lateral: bool) -> _OpenLoop:
    """``periods`` control periods from the warm-up's end at ``t0`` (s); ``plans``: period
    index -> plan set at that period's start."""
    from arzsumo.sumo.network import MAIN
    from arzsumo.sumo.period_reads import OpenLoopPeriod, OpenLoopReads

    cells, main, releases = [], [], []

    def keep(p: OpenLoopPeriod) -> None:
        if p.measurement is None:   # pragma: no cover - the premise's sensor measures
            raise PremiseRunError("the premise runs need the sensor's measurement")
        cells.append(p.measurement.cells)
        releases.append(p.releases)
        main.append(p.vehicles[MAIN])

    cfg = plant.cfg
    plant.meter.start_window()
    end = plant.run_open_loop(periods, keep, plans=[(t0 + k * cfg.control_period, plan)
                                                   for k, plan in plans.items()],
                              reads=OpenLoopReads(edges=(MAIN,), lateral=lateral))
    return _OpenLoop(t0, cells, main, releases, end.lateral, plant.sim.take_report(),
                     plant.meter.summary(), cfg)


def _grid(rec: _OpenLoop) -> dict[str, Any]:
    c0 = rec.cells[0]
    return {"t0_s": rec.t0, "t_s": [c.t for c in rec.cells], "x_m": c0.x.tolist(),
            "dx_m": float(c0.x[1] - c0.x[0]) if c0.x.size > 1 else rec.cfg.cell_length,
            "period_s": rec.cfg.control_period}


def _fields_row(rec: _OpenLoop) -> dict[str, Any]:
    """The speed fields per class (periods x cells, m/s) on their grid."""
    return {**_grid(rec), "v_hv": np.array([c.v_h for c in rec.cells]).tolist(),
            "v_av": np.array([c.v_a for c in rec.cells]).tolist()}


def _baseline_row(sc: Scenario, rec: _OpenLoop) -> dict[str, Any]:
    """The fields, counts, coupling gates, SUMO's accounting and the ramp queue."""
    from arzsumo_studies.gates import coupling_gate

    dx = rec.cfg.cell_length
    lat = rec.lateral
    t = np.repeat(lat.t, lat.counts)
    coupling, samples = [], {}
    for name, mask in (("hv", ~lat.av), ("av", lat.av)):
        samples[name] = int(mask.sum())
        if samples[name] >= 2:
            coupling.append(coupling_gate(t[mask], lat.pos[mask], lat.lat[mask],
                                          lat.speed[mask], name).as_dict())
    rep, cfg = rec.report, rec.cfg
    storage = cfg.ramp_storage if cfg.ramp_storage > 0 else ramp_capacity()
    return {**_fields_row(rec),
            "count_veh": [float((c.rho_h.sum() + c.rho_a.sum()) * dx) for c in rec.cells],
            "main_vehicles": rec.main_vehicles, "lateral_counts": lat.counts.tolist(),
            "lateral_samples": int(lat.counts.sum()), "class_samples": samples,
            "coupling": coupling,
            "rho_hv_veh_m": float(np.nanmean([c.rho_h.mean() for c in rec.cells])),
            "rho_av_veh_m": float(np.nanmean([c.rho_a.mean() for c in rec.cells])),
            "outflow_veh_s": float(np.mean([c.outflow_h + c.outflow_a for c in rec.cells])),
            "inserted_main": rep.inserted - rep.inserted_ramp,
            "requested_main": rep.requested - rep.requested_ramp,
            "collisions": rep.collisions, "ramp_demand_veh_s": cfg.ramp_demand,
            "max_release_veh_s": cfg.release_rate_max if cfg.meter_mode == "one_per_green"
            else None, "meter_mode": cfg.meter_mode,
            "max_queue_veh": int(rec.meter["max_queue"]), "ramp_storage_veh": storage}


def _staircase(sc: Scenario, plant: SumoPlant, t0: float,
               opt: Mapping[str, Any]) -> dict[str, Any]:
    """The release-rate staircase: q(L), the commanded r and the releases per period."""
    from arzsumo.bridge.session import meter_curve_of

    cfg, period = sc.sumo, sc.sumo.control_period
    per_level = _periods(opt["level_s"], period)
    steps = staircase_levels(int(opt["levels"]))
    curve = meter_curve_of(cfg, sc.source)
    dr = float(opt["step_veh_s"])
    plans = {i * per_level: plan_for_step(cfg, curve, s * dr) for i, s in enumerate(steps)}
    rec = _window(plant, t0, per_level * len(steps), plans, lateral=False)
    rate = np.repeat([cfg.release_rate + s * dr for s in steps], per_level)
    released = np.diff(np.r_[0, rec.releases]) / period
    return {**_grid(rec), "q_veh_s": [c.outflow_h + c.outflow_a for c in rec.cells],
            "r_veh_s": rate.tolist(), "released_veh_s": released.tolist(),
            "step_times_s": [rec.t0 + i * per_level * period
                             for i in range(1, len(steps))],
            "meter_mode": cfg.meter_mode}
