"""The closed loop in SUMO: sense, estimate, decide, actuate; two PDE twins alongside.

:func:`run_cosimulation` (``arzsumo run``) runs the :class:`~arzsumo.bridge.prepared.PreparedRun`
that :func:`arzsumo.bridge.session.prepare_run` checked once; every stage reads the run's
configuration from it alone:

1. (those checks)
2. Start SUMO, with vehicles placed from ``[initial]`` if asked (:func:`open_run`).
3. Warm up at the nominal plan, for the warm-up rounded up to whole control periods (at
   least one; :func:`warm_start`). It does not depend on the controller, so several
   controllers can continue one (:mod:`arzsumo.bridge.branches`).
4. With ``equilibrium = "measured"``, the mean Edie densities of the warm-up's last 60 s
   are the model's equilibrium; its regime and the dead time are checked at it.
5. Build the controller, the actuator and both twins from the measured state at t = 0.
6. Every control period: :class:`~arzsumo.bridge.loop.ClosedLoop`.
7. After the window, with ``[sumo] drain_max_s`` > 0, the drain (:mod:`arzsumo.bridge.drain`).

Steps 4-7 are :func:`finish_run`. The meter's counts cover the control window only (the
warm-up's: ``CoSimResult.warmup_meter``). SUMO's own outputs, written to a scratch
directory, become the network measures (:mod:`arzsumo.sumo.window`).
"""

from __future__ import annotations

import math
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.bridge.actuator import on_meter
from arzsumo.bridge.delay import check_delay, compensate
from arzsumo.bridge.drain import drain, whole_demand
from arzsumo.bridge.estimators import RecordedEstimator, estimation_stage
from arzsumo.bridge.loop import ClosedLoop
from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.records import Trace, columns, micro_fields
from arzsumo.bridge.reference import reference_shift
from arzsumo.bridge.result import CoSimResult
from arzsumo.bridge.run_progress import CONTROL, MEASURES, run_progress
from arzsumo.bridge.speed_actuator import actuator_for
from arzsumo.bridge.trigger_noise import size_dead_band, warmup_states
from arzsumo.bridge.twins import TwinPair
from arzsumo.control.alinea import ReleaseRates
from arzsumo.control.base import Controller
from arzsumo.control.registry import ControllerInputs, controller_spec, is_pde
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.evaluation.decay import stationary_reference
from arzsumo.model.characteristic import Linearization, linearize
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import ModelParameters
from arzsumo.pde.solver import SolverOptions
from arzsumo.pde.state import cell_centres
from arzsumo.progress import Progress, RunProgress
from arzsumo.scenario import Scenario
from arzsumo.scenario.run import RunSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network_measures import network_options
from arzsumo.sumo.paths import scratch_dir
from arzsumo.sumo.period_reads import OpenLoopPeriod
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.run_files import FCD_FILE, RunFiles
from arzsumo.sumo.sensor import PeriodMeasurement
from arzsumo.sumo.simulation import SumoSimulation, open_simulation
from arzsumo.sumo.window import NetworkMeasures, WindowStart, measure_network
from arzsumo.units import ms_to_kmh

#: seconds of warm-up averaged for a measured equilibrium
MEASURE_WINDOW = 60.0


def check_before_start(settings: RunSettings, eq: Equilibrium, at: str | None = None,
                       at_eq: str = "this equilibrium") -> Linearization:
    """Refuse a PDE controller at a free-flow equilibrium (lambda_4 >= 0), before SUMO runs;
    the refusal names the controller as ``at`` (default ``controller = 'NAME'``) and the
    equilibrium as ``at_eq``."""
    lin = linearize(eq)
    if is_pde(settings.controller) and lin.regime != "congested":
        who = at or f"controller = {settings.controller!r}"
        raise ScenarioError(
            f"{who} is not allowed at {at_eq}: "
            f"lambda_4 = {ms_to_kmh(lin.eigenvalues[3]):.2f} km/h >= 0 (free flow); PDE "
            "boundary control needs congestion (lambda_4 < 0); use 'open' or 'alinea'")
    return lin


def warm_up(plant: SumoPlant, warmup: float, period: float,
            bar: Progress | RunProgress) -> list[PeriodMeasurement]:
    """``warmup`` seconds (rounded up to whole periods, at least one) at the nominal plan:
    the open loop (:meth:`~arzsumo.sumo.plant.SumoPlant.run_open_loop`), every period's
    measurement."""
    out: list[PeriodMeasurement] = []

    def keep(p: OpenLoopPeriod) -> None:
        if p.measurement is not None:      # the closed loop's sensor always measures
            out.append(p.measurement)
            bar.update(p.t)

    plant.run_open_loop(max(1, math.ceil(warmup / period - 1e-9)), keep)
    return out


def operating_point(settings: RunSettings, eq: Equilibrium,
                    warm: list[PeriodMeasurement], period: float) -> Equilibrium:
    """The design equilibrium: the scenario's, or the mean of the warm-up's last 60 s."""
    if settings.equilibrium != "measured":
        return eq
    k = max(1, round(MEASURE_WINDOW / period))
    rho_h = float(np.mean([w.cells.rho_h.mean() for w in warm[-k:]]))
    rho_a = float(np.mean([w.cells.rho_a.mean() for w in warm[-k:]]))
    try:
        measured = Equilibrium(eq.params, rho_h, rho_a)
    except ArzsumoError as exc:
        raise ScenarioError(f"the measured operating point is not an admissible "
                            f"equilibrium of the model: {exc}") from None
    check_before_start(settings, measured, at_eq="the measured operating point")
    return measured


def build_controller(name: str, lin: Linearization, kernels: Any,
                     run: PreparedRun) -> Controller:
    """A reset controller of ``name`` for the closed loop (the registry's builder), with
    the run's ``[design]`` and ``[alinea]``; the ``constant`` controller holds the release
    rate ``[run] constant_release_veh_h``."""
    cfg = run.sumo
    rates = ReleaseRates(cfg.release_rate, cfg.release_rate_min, cfg.release_rate_max)
    inputs = ControllerInputs(lin, kernels, run.design,
                              constant_u=cfg.release_rate - run.settings.constant_release,
                              alinea=run.scenario.alinea, rates=rates,
                              check_period=cfg.control_period)
    ctrl = controller_spec(name, "sumo").build(inputs)
    ctrl.reset()
    return ctrl


def place_initial(params: ModelParameters, settings: RunSettings, cfg: SumoConfig,
                  initial_fields: np.ndarray | None) -> tuple[list, str]:
    """Vehicles to place at t = 0 and a one-line report ("none" without placement)."""
    if settings.start != "placement":
        return [], "none"
    from arzsumo.sumo.placement import place_vehicles

    if initial_fields is None:
        raise ScenarioError("start = 'placement' needs an [initial] profile")
    xc = cell_centres(params.length, initial_fields.shape[1])
    initial, rep = place_vehicles(params, cfg, xc, *initial_fields)
    return initial, rep.summary()


@dataclass
class Warmed:
    """The end of the warm-up (step 3 of the module docstring), the same for every
    controller, and the state of the system as the control window opens."""

    plant: SumoPlant
    warm: list[PeriodMeasurement]
    warmup_meter: dict[str, float]
    start: WindowStart


def warm_start(sim: SumoSimulation, run: PreparedRun, bar: RunProgress) -> Warmed:
    """The warm-up of ``run`` in the open ``sim``, and the control window opened at its
    end."""
    scenario, cfg = run.scenario, run.sumo
    est = scenario.estimation
    plant = SumoPlant(sim, scenario.params.length, cfg, run.curve, layout=scenario.sensing,
                      loop_noise=est.loop_noise, probe_noise=est.probe_noise, window=True)
    warm = warm_up(plant, run.settings.warmup, cfg.control_period, bar)
    plant.timings = dict.fromkeys(plant.timings, 0.0)   # time the control window only
    counts, start = plant.start_window(warm[-1].t)
    return Warmed(plant, warm, {**counts, "duration_s": float(warm[-1].t)}, start)


@dataclass
class Controlled:
    """What the warm-up and the control window left: the loop (plant, controller, twins),
    the design point, the warm-up's meter counts and the window's start."""

    loop: ClosedLoop
    ref_ctrl: Controller
    eq: Equilibrium
    q_nom: float
    warmup_meter: dict[str, float]
    start: WindowStart
    estimator: RecordedEstimator
    settings: RunSettings
    stationary: tuple[np.ndarray, float]   # the warm-up's state and band (evaluation.decay)
    trigger_noise: float | None = None     # veh/s: the law's output noise sizing the dead band
    law: Controller | None = None          # the law built for the run (given to in_loop)

    @property
    def trace(self) -> Trace:
        """The loop's trace (opened by :meth:`ClosedLoop.begin`)."""
        if self.loop.trace is None:
            raise RuntimeError("the control window has not begun (ClosedLoop.begin)")
        return self.loop.trace


@dataclass
class OpenRun:
    """A started run: SUMO, where its outputs go, the files kept for its results."""

    sim: SumoSimulation
    out_dir: Path          # SUMO's tripinfo, edge data, statistics (and FCD)
    files: RunFiles
    bar: RunProgress
    placement: str
    wall0: float


@contextmanager
def open_run(run: PreparedRun, *, progress: bool | RunProgress = False,
             frontend: str = "libsumo") -> Iterator[OpenRun]:
    """SUMO started for the warm-up plus the control horizon of ``run`` with the run's
    outputs, vehicles placed from ``run.initial`` with ``start = "placement"`` (step 2 of
    the module docstring); its scratch directory goes on leaving, its kept files too
    when leaving on an error. ``progress``: draw the run's phases on stderr; a
    :class:`~arzsumo.progress.RunProgress` given is drawn on and left open for the
    caller's own phases (``arzsumo run`` writing its results)."""
    wall0 = time.perf_counter()
    scenario, settings, cfg = run.scenario, run.settings, run.sumo
    run_cfg = cfg.with_(horizon=settings.warmup + cfg.horizon)
    initial, placement = place_initial(scenario.params, settings, run_cfg, run.initial)
    bar = (progress if isinstance(progress, RunProgress)
           else run_progress(settings, cfg, enabled=progress))
    net_dir = Path(tempfile.mkdtemp(prefix="arzsumo-net-", dir=scratch_dir()))
    files = RunFiles()
    try:
        with open_simulation(scenario.params, run_cfg, initial=initial,
                             extra_args=network_options(net_dir, fcd=cfg.fcd),
                             output_dir=net_dir, keep=files, frontend=frontend,
                             loops=scenario.sensing.loop_x(scenario.params.length),
                             downstream_loop=scenario.alinea.loop_distance) as sim:
            yield OpenRun(sim, net_dir, files, bar, placement, wall0)
    except BaseException:
        files.remove()
        bar.abandon()
        raise
    finally:
        shutil.rmtree(net_dir, ignore_errors=True)
        if bar is not progress:
            bar.close()


def run_cosimulation(run: PreparedRun, *, progress: bool | RunProgress = False,
                     keep_measurements: bool = False,
                     frontend: str = "libsumo") -> CoSimResult:
    """Run SUMO with the controller of ``run`` and both twins (module docstring).

    ``progress`` as in :func:`open_run`; ``keep_measurements`` keeps every period's
    measurement, warm-up included, in ``estimator.measurements`` (offline estimation,
    :mod:`arzsumo_studies.estimation.sensor_record`); ``frontend``: "libsumo", "traci" or "gui"
    (:mod:`arzsumo.sumo.frontend`). The result keeps the run's SUMO configuration and,
    with ``[sumo] fcd``, its FCD output in ``files`` (:mod:`arzsumo.sumo.run_files`).
    """
    with open_run(run, progress=progress, frontend=frontend) as opened:
        return finish_run(opened, warm_start(opened.sim, run, opened.bar), run, keep_measurements)


def finish_run(opened: OpenRun, warmed: Warmed, run: PreparedRun,
               keep_measurements: bool = False) -> CoSimResult:
    """From the end of the warm-up: the control window of ``run`` and what
    :func:`close_window` does (steps 4-7 of the module docstring)."""
    return close_window(opened, control(warmed, run, opened.bar, keep_measurements), run)


def close_window(opened: OpenRun, c: Controlled, run: PreparedRun) -> CoSimResult:
    """After the control window ``c``: the drain, SUMO closed, and the network measures
    read from SUMO's outputs (step 7 of the module docstring)."""
    sim, cfg = opened.sim, run.sumo
    plant = c.loop.plant
    meter_summary = {**plant.meter_summary(), "ramp_storage": cfg.ramp_storage,
                     **c.loop.actuator.summary()}
    c.loop.actuator.restore()         # the drain runs the open loop's outlet
    timings = {**plant.timings, **c.loop.timings}   # the window's, not the drain's
    t_end = sim.time
    drained = drain(plant, cfg.drain_max, opened.bar) if cfg.drain_max > 0 else None
    opened.bar.enter(MEASURES)
    sim.close()                # SUMO writes the unfinished trips' tripinfo as it closes
    outlet = round(sum((r.outflow_h + r.outflow_a) * cfg.control_period for r in c.trace.records))
    network, trips = measure_network(opened.out_dir, c.start, t_end, outlet,
                                     drained.end if drained else None, sim.time,
                                     **outlet_edge(cfg, sim))
    if drained is not None:
        network = whole_demand(network, trips, plant, drained)
    if cfg.fcd:   # moved, not read: an FCD file is large
        opened.files.adopt(opened.out_dir / FCD_FILE, FCD_FILE)
    return _result(c, run.scenario, cfg, meter_summary, sim, network, opened.placement,
                   opened.files, timings, time.perf_counter() - opened.wall0)


def outlet_edge(cfg: SumoConfig, sim: SumoSimulation | None = None) -> dict[str, Any]:
    """``{"outlet_edge": the last section edge, "ramp": ramp vehicles by route, as ``sim``
    recorded them}`` on a user's network; {} on the shipped one (``main``, ids ``ramp...``)."""
    if cfg.layout is None:
        return {}
    return {"outlet_edge": cfg.layout.section_edges[-1],
            **({"ramp": sim.classes.recorded} if sim is not None else {})}


def _result(c: Controlled, scenario: Scenario, cfg: SumoConfig, meter: dict[str, Any],
            sim: SumoSimulation, network: NetworkMeasures, placement: str, files: RunFiles,
            timings: dict[str, float], wall_time: float) -> CoSimResult:
    """The :class:`CoSimResult` of a finished run."""
    loop, trace = c.loop, c.trace
    sensor = loop.plant.sensor
    return CoSimResult(
        scenario=scenario, settings=c.settings, sumo=cfg, equilibrium=c.eq,
        q_nominal=c.q_nom, t=np.asarray(trace.t), x=trace.x, micro=np.asarray(trace.micro),
        replay=np.asarray(trace.replay), reference=np.asarray(trace.reference),
        periods=columns(trace.records), controller_log=loop.controller.log,
        reference_log=c.ref_ctrl.log, meter=meter, report=sim.report,
        twin_status=loop.twins.status(), placement=placement, wall_time=wall_time,
        timings=timings, warmup_meter=c.warmup_meter,
        network=network, section_speed=sensor.speeds.summary(), start=trace.start,
        estimate=np.asarray(c.estimator.fields[1:]), estimator=c.estimator,
        shift=loop.shift, lateral=sensor.lateral.record(), files=files,
        disturbance=(dict(loop.plant.disturbance.applied) if loop.plant.disturbance
                     else None), stationary=c.stationary[0], stationary_band=c.stationary[1],
        trigger_noise=c.trigger_noise)


#: builds the controller the loop checks from the law built for the run (an outside
#: driver's stand-in, :mod:`arzsumo.gym`); None: the law itself
InLoop = Callable[[Controller], Controller]


def control(warmed: Warmed, run: PreparedRun, bar: RunProgress,
            keep_measurements: bool = False) -> Controlled:
    """The control window of ``run`` from the end of the warm-up (steps 4-6 of the module
    docstring); ``run.sumo`` has the control horizon."""
    c = open_window(warmed, run, bar, keep_measurements)
    c.loop.run(warmed.warm[-1], run.sumo.horizon, bar)
    return c


def open_window(warmed: Warmed, run: PreparedRun, bar: RunProgress,
                keep_measurements: bool = False, in_loop: InLoop | None = None
                ) -> Controlled:
    """The control window of ``run`` set up at the end of the warm-up (steps 4-5 of the
    module docstring), before its first check: the loop (not yet begun), the law built
    for the run (``Controlled.law``; the loop checks ``in_loop(law)`` when given) and
    ``Controlled.trace``, the loop's trace once :meth:`ClosedLoop.begin` opened it."""
    from arzsumo.kernel_cache import cached_kernels

    scenario, settings, cfg = run.scenario, run.settings, run.sumo
    period, est = cfg.control_period, scenario.estimation
    plant, warm = warmed.plant, warmed.warm
    bar.enter(CONTROL, offset=warm[-1].t)    # solving the kernels is the window's cost
    eq = operating_point(settings, scenario.equilibrium, warm, period)
    lin = linearize(eq)
    kernels = (cached_kernels(lin.system, settings.kernel_cells)
               if is_pde(settings.controller) else None)
    estimator, acting = estimation_stage(scenario.estimation, scenario.sensing,
                                         settings.controller, eq, warm[-1].cells.x,
                                         keep_measurements)
    warm_fields = estimator.prime(warm[:-1], warm[-1].t)
    shift = (reference_shift(est.reference, warm_fields, eq, est.reference_window, period)
             if is_pde(acting) and est.reference != "equilibrium" and warm_fields else None)
    if eq is not scenario.equilibrium:     # prepare_run checked the scenario's
        check_delay(scenario, acting, lin.eigenvalues, "measured")
    ctrl = on_meter(compensate(build_controller(acting, lin, kernels, run), acting,
                               scenario), acting, scenario.actuation)
    trigger_noise = (size_dead_band(ctrl, warmup_states(
        warm_fields, warm[-1].cells.x, period, est.reference_window, shift))
        if run.design.noise_from_estimate and is_pde(acting) and warm_fields else None)
    ref_name = settings.controller if is_pde(settings.controller) else "open"
    ref_ctrl = build_controller(ref_name, lin, kernels, run)
    q_nom = run.curve.outflow_at(cfg.green_share)
    opts = SolverOptions(cells=settings.twin_cells, scheme=settings.twin_scheme,
                         horizon=cfg.horizon, control_period=period)
    twins = TwinPair(eq, lin, warm[-1].cells, opts, settings.smoothing, ref_ctrl, q_nom)
    act = scenario.actuation
    actuator = actuator_for(plant, q_nom, settings.controller, acting, act, period)
    loop = ClosedLoop(plant, estimator, in_loop(ctrl) if in_loop else ctrl, actuator, twins,
                      period, act.anti_windup, shift)
    plant.disturb(scenario.disturbance, warm[-1].t)
    tail = warm[-max(1, round(est.reference_window / period)):]
    stationary = stationary_reference(np.stack([micro_fields(m.cells) for m in tail]),
                                      period)
    return Controlled(loop, ref_ctrl, eq, q_nom, warmed.warmup_meter,
                      warmed.start, estimator, settings, stationary, trigger_noise, ctrl)
