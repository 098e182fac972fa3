"""The closed loop in SUMO: sense, estimate, decide, actuate; two PDE twins alongside.

Sequence of :func:`run_cosimulation` (``arzsumo run``):

1. Refuse a PDE controller at a free-flow equilibrium (lambda_4 >= 0) before SUMO starts
   (with ``equilibrium = "scenario"``).
2. Start SUMO, with vehicles placed from the scenario's ``[initial]`` profile if asked.
3. Warm up: the same period loop as control, under the nominal meter plan, for the
   warm-up rounded up to whole control periods (at least one, to measure from).
4. With ``equilibrium = "measured"``, take the mean Edie densities of the last 60 s of the
   warm-up as the equilibrium of the (calibrated) model, and check its regime.
5. Build the controller (kernels solved or loaded; ALINEA's settings from ``[alinea]``),
   the actuator and both twins from the measured state at the start of control.
6. Every control period: the controller is checked on the estimate of the last period
   (:mod:`~arzsumo.bridge.estimator`; with ``[estimation] method`` "smoothing" or "enkf"
   built from the ``[sensing]`` loops and AV probes, fed the warm-up's records first:
   :mod:`~arzsumo.bridge.estimators`) and its U goes to the meter
   (:mod:`~arzsumo.bridge.actuator`); SUMO runs one period, read by the sensor
   (:mod:`arzsumo.sumo.sensor`); the twins (:mod:`~arzsumo.bridge.twins`) advance; one
   :class:`~arzsumo.bridge.records.PeriodRecord` is kept. No command follows the last
   check (no period follows it: a plan change there would never run).

The meter's counts (plan and light changes, queue maximum) cover the control window only:
the meter's window is closed at the start of control and the warm-up's counts are kept
apart (``CoSimResult.warmup_meter``).

SUMO writes its own outputs (tripinfo of every loaded vehicle with emissions, edge data,
statistics; :func:`~arzsumo.sumo.network_measures.network_options`) into a scratch
directory; after the run they become the network measures of the control window and of
the whole run (:mod:`arzsumo.sumo.window`, ``CoSimResult.network``), the sensor's speed
moments of the section (``CoSimResult.section_speed``; its lateral snapshots:
``CoSimResult.lateral``), and the compressed tripinfo kept with the results. The run's
SUMO configuration (``run.sumocfg`` and its files) and, with ``[sumo] fcd``, SUMO's FCD
output are kept in ``CoSimResult.files`` (:mod:`arzsumo.sumo.run_files`) for the results
directory.

A detector sample's path: ``SumoSensor.observe`` (libsumo, every step) ->
``PeriodMeasurement`` -> ``Estimator.estimate`` -> ``MacroState`` -> ``Controller.check``
-> U -> ``MeterActuator.apply`` (the ``[actuation]`` limits; the U applied goes back to
``Controller.applied``, and to a delay compensator, ``Controller.actuated``:
:mod:`~arzsumo.bridge.delay`) -> ``RampMeter.command_outflow`` (or a release rate,
``OnePerGreenMeter.command_rate``) -> the light, set by ``step`` at the next cycle start.
"""

from __future__ import annotations

import logging
import math
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.bridge.actuator import ActuationLimits, MeterActuator
from arzsumo.bridge.delay import check_delay, compensate
from arzsumo.bridge.drain import drain, whole_demand
from arzsumo.bridge.estimator import Estimator
from arzsumo.bridge.estimators import RecordedEstimator, estimation_stage
from arzsumo.bridge.records import Decision, PeriodRecord, Trace, columns, micro_fields
from arzsumo.bridge.reference import ReferenceShift, reference_shift
from arzsumo.bridge.result import CoSimResult
from arzsumo.bridge.twins import TwinPair
from arzsumo.control.alinea import AlineaSettings, ReleaseRates
from arzsumo.control.base import Controller, MacroState
from arzsumo.control.etc import EtcDesign
from arzsumo.control.registry import ControllerInputs, controller_spec, is_pde
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.model.characteristic import Linearization, linearize
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import ModelParameters
from arzsumo.progress import Progress
from arzsumo.scenario import Scenario
from arzsumo.scenario.run import RunSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.meter import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sumo.meter_release import make_meter
from arzsumo.sumo.network_measures import network_options
from arzsumo.sumo.paths import scratch_dir
from arzsumo.sumo.run_files import FCD_FILE, RunFiles
from arzsumo.sumo.sensor import PeriodMeasurement, SumoSensor
from arzsumo.sumo.simulation import SumoSimulation, open_simulation
from arzsumo.sumo.window import WindowStart, measure_network
from arzsumo.twin.solver import SolverOptions

log = logging.getLogger(__name__)

#: seconds of warm-up averaged for a measured equilibrium
MEASURE_WINDOW = 60.0


def check_before_start(settings: RunSettings, eq: Equilibrium) -> Linearization:
    """Refuse a PDE controller at a free-flow equilibrium (lambda_4 >= 0), before SUMO runs."""
    lin = linearize(eq)
    if is_pde(settings.controller) and lin.regime != "congested":
        raise ScenarioError(
            f"controller = {settings.controller!r} is not allowed at this equilibrium: "
            f"lambda_4 = {lin.eigenvalues[3] * 3.6:.2f} km/h >= 0 (free flow); PDE "
            "boundary control needs congestion (lambda_4 < 0); use 'open' or 'alinea'")
    return lin


class SumoPlant:
    """SUMO with its sensor and meter, advanced one control period at a time."""

    def __init__(self, sim: SumoSimulation, length: float, cfg: SumoConfig,
                 curve: GreenShareCurve, scenario: Scenario | None = None) -> None:
        self.sim = sim
        self.meter = make_meter(sim.lib, cfg, curve)
        est = scenario.estimation if scenario else None
        self.sensor = SumoSensor(sim.lib, length, cfg, window=True,
                                 layout=scenario.sensing if scenario else None,
                                 loop_noise=est.loop_noise if est else None,
                                 probe_noise=est.probe_noise if est else None)
        self.timings = {"sumo_step": 0.0, "measure_actuate": 0.0}

    def advance(self) -> PeriodMeasurement:
        """Step SUMO to the end of the current control period; its measurement."""
        while True:
            s0 = time.perf_counter()
            t = self.sim.step()
            s1 = time.perf_counter()
            got = self.sensor.observe(t, self.sim.pending)
            self.meter.step(self.sensor.queue)
            s2 = time.perf_counter()
            self.timings["sumo_step"] += s1 - s0
            self.timings["measure_actuate"] += s2 - s1
            if got is not None:
                return got


def warm_up(plant: SumoPlant, warmup: float, period: float,
            bar: Progress) -> list[PeriodMeasurement]:
    """``warmup`` seconds (rounded up to whole periods, at least one) at the nominal plan."""
    out = []
    for _ in range(max(1, math.ceil(warmup / period - 1e-9))):
        out.append(plant.advance())
        bar.update(out[-1].t)
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
    check_before_start(settings, measured)
    return measured


def meter_rates(cfg: SumoConfig) -> ReleaseRates:
    """The meter's nominal release rate and bounds (veh/s): ALINEA's and the held meter's
    r_nominal, r_min, r_max (U = r_nominal - r)."""
    return ReleaseRates(cfg.release_rate, cfg.release_rate_min, cfg.release_rate_max)


def build_controller(name: str, lin: Linearization, kernels: Any, design: EtcDesign,
                     settings: RunSettings, cfg: SumoConfig,
                     alinea: AlineaSettings) -> Controller:
    """A reset controller of ``name`` for the closed loop (the registry's builder); the
    ``constant`` controller holds the release rate ``[run] constant_release_veh_h``."""
    inputs = ControllerInputs(lin, kernels, design,
                              constant_u=cfg.release_rate - settings.constant_release,
                              alinea=alinea, rates=meter_rates(cfg),
                              check_period=cfg.control_period)
    ctrl = controller_spec(name, "sumo").build(inputs)
    ctrl.reset()
    return ctrl


class ClosedLoop:
    """The stages of the control window, wired together (see the module docstring)."""

    def __init__(self, plant: SumoPlant, estimator: Estimator, controller: Controller,
                 actuator: MeterActuator, twins: TwinPair, period: float,
                 anti_windup: bool = True, shift: ReferenceShift | None = None) -> None:
        self.plant, self.estimator, self.controller = plant, estimator, controller
        self.actuator, self.twins, self.period = actuator, twins, period
        self.anti_windup, self.shift = anti_windup, shift
        self.timings = {"controller": 0.0, "twins": 0.0, "estimator": 0.0}

    def decide(self, state: MacroState, final: bool) -> Decision:
        """Check the controller and the reference twin's; command the meter unless this
        is the ``final`` check."""
        c0 = time.perf_counter()
        u = self.controller.check(self.shift.apply(state) if self.shift else state)
        c1 = time.perf_counter()
        u_ref = self.twins.check_reference()
        self.timings["controller"] += c1 - c0
        self.timings["twins"] += time.perf_counter() - c1
        log_ = self.controller.log
        u_cont = log_.u_continuous[-1] if log_.u_continuous else u
        triggered = float(log_.triggered[-1]) if log_.triggered else 0.0
        if final:
            return Decision(state.t, u, u_cont, triggered, self.plant.meter.green_share,
                            u_ref, c1 - c0)
        act = self.actuator.apply(u)
        self.controller.actuated(act.u_applied)
        if self.anti_windup:
            self.controller.applied(act.u_applied, act.lower, act.upper)
        rate = self.plant.meter.release_rate
        return Decision(state.t, u, u_cont, triggered, act.green, u_ref, c1 - c0,
                        act.u_applied, float(act.saturated), float(act.rate_limited),
                        math.nan if rate is None else rate)

    def record(self, d: Decision, m: PeriodMeasurement) -> PeriodRecord:
        meter, c = self.plant.meter, m.cells
        return PeriodRecord(d.t, d.u_applied, d.u_continuous, d.triggered,
                            d.green_commanded, meter.green_share, meter.light_changes,
                            meter.plan_changes, meter.queue, meter.max_queue, c.inflow_h,
                            c.inflow_a, c.outflow_h, c.outflow_a, m.occupancy_out,
                            d.u_reference, d.controller_s, d.u, d.u_applied, d.saturated,
                            d.rate_limited, m.flow_out_loop, d.release_rate,
                            float(meter.override()))

    def run(self, start: PeriodMeasurement, horizon: float, bar: Progress) -> Trace:
        """Control from the measurement ``start`` (t = 0) until ``horizon`` seconds."""
        t0, trace = start.t, Trace(start.cells.x, micro_fields(start.cells))
        state = self.estimator.estimate(start, 0.0)
        while True:
            final = state.t >= horizon - 1e-9
            decision = self.decide(state, final)
            if final:
                return trace
            m = self.plant.advance()
            t = m.t - t0
            w0 = time.perf_counter()
            self.twins.advance(m.cells, t, self.period, decision.u_reference)
            self.timings["twins"] += time.perf_counter() - w0
            c = m.cells
            trace.records.append(self.record(decision, m))
            trace.t.append(t)
            trace.micro.append(micro_fields(c))
            trace.replay.append(self.twins.replay.sample(trace.x))
            trace.reference.append(self.twins.reference.sample(trace.x))
            e0 = time.perf_counter()
            state = self.estimator.estimate(m, t)
            self.timings["estimator"] += time.perf_counter() - e0
            bar.update(m.t)


def place_initial(params: ModelParameters, settings: RunSettings, cfg: SumoConfig,
                  initial_fields: np.ndarray | None) -> tuple[list, str]:
    """Vehicles to place at t = 0 and a one-line report ("none" without placement)."""
    if settings.start != "placement":
        return [], "none"
    from arzsumo.sumo.placement import place_vehicles

    if initial_fields is None:
        raise ScenarioError("start = 'placement' needs an [initial] profile")
    n = initial_fields.shape[1]
    xc = (np.arange(n) + 0.5) * params.length / n
    initial, rep = place_vehicles(params, cfg, xc, *initial_fields)
    return initial, rep.summary()


@dataclass
class Controlled:
    """What the warm-up and the control window left: the loop (plant, controller, twins),
    its trace, the design point, the warm-up's meter counts and the window's start."""

    loop: ClosedLoop
    trace: Trace
    ref_ctrl: Controller
    eq: Equilibrium
    q_nom: float
    warmup_meter: dict[str, float]
    start: WindowStart
    estimator: RecordedEstimator


def run_cosimulation(scenario: Scenario, settings: RunSettings, cfg: SumoConfig,
                     design: EtcDesign, *, initial_fields: np.ndarray | None = None,
                     curve: GreenShareCurve = DEFAULT_CURVE,
                     progress: bool = False, keep_measurements: bool = False,
                     frontend: str = "libsumo") -> CoSimResult:
    """Run SUMO with the controller of ``settings`` and both twins (module docstring).

    ``initial_fields`` (4, cells on the micro grid) places vehicles at t = 0 when
    ``settings.start == "placement"``. ``keep_measurements``: keep every period's
    measurement, warm-up included, in ``estimator.measurements`` (for offline estimation,
    :mod:`arzsumo.bridge.sensor_record`). ``frontend``: "libsumo", "traci" or "gui"
    (watch the run in sumo-gui; :mod:`arzsumo.sumo.frontend`). The run's SUMO
    configuration, and with ``cfg.fcd`` its FCD output, are kept in ``files``
    (:mod:`arzsumo.sumo.run_files`).
    """
    wall0 = time.perf_counter()
    if settings.equilibrium == "scenario":
        check_before_start(settings, scenario.equilibrium)
    run_cfg = cfg.with_(horizon=settings.warmup + cfg.horizon)
    initial, placement = place_initial(scenario.params, settings, run_cfg, initial_fields)
    bar = Progress(run_cfg.horizon, f"{settings.controller} seed {cfg.seed}",
                   enabled=progress)
    net_dir = Path(tempfile.mkdtemp(prefix="arzsumo-net-", dir=scratch_dir()))
    files = RunFiles()
    try:
        with open_simulation(scenario.params, run_cfg, initial=initial,
                             extra_args=network_options(net_dir, fcd=cfg.fcd),
                             output_dir=net_dir, keep=files, frontend=frontend,
                             loops=scenario.sensing.loop_x(scenario.params.length),
                             downstream_loop=scenario.alinea.loop_distance) as sim:
            c = control(sim, scenario, settings, cfg, design, curve, bar, keep_measurements)
            meter = c.loop.plant.meter
            meter_summary = {**meter.summary(), "ramp_storage": cfg.ramp_storage}
            t_end = sim.time
            drained = drain(sim, meter, cfg.drain_max) if cfg.drain_max > 0 else None
        records = c.trace.records
        outlet = round(sum((r.outflow_h + r.outflow_a) * cfg.control_period for r in records))
        network, trips = measure_network(net_dir, c.start, t_end, outlet,
                                         drained.end if drained else None, sim.time)
        if drained is not None:
            network = whole_demand(network, trips, meter, sim, drained)
        if cfg.fcd:   # moved, not read: an FCD file is large
            files.adopt(net_dir / FCD_FILE, FCD_FILE)
    except BaseException:
        files.remove()
        raise
    finally:
        shutil.rmtree(net_dir, ignore_errors=True)
    bar.close()
    loop, trace = c.loop, c.trace
    return CoSimResult(scenario, settings, cfg, c.eq, c.q_nom, np.asarray(trace.t), trace.x,
                       np.asarray(trace.micro), np.asarray(trace.replay),
                       np.asarray(trace.reference), columns(records), loop.controller.log,
                       c.ref_ctrl.log, meter_summary, sim.report, loop.twins.status(),
                       placement, time.perf_counter() - wall0,
                       {**loop.plant.timings, **loop.timings}, c.warmup_meter, network,
                       loop.plant.sensor.speeds.summary(), trace.start,
                       np.asarray(c.estimator.fields[1:]), c.estimator,
                       loop.shift, loop.plant.sensor.lateral.record(), files)


def control(sim: SumoSimulation, scenario: Scenario, settings: RunSettings, cfg: SumoConfig,
            design: EtcDesign, curve: GreenShareCurve, bar: Progress,
            keep_measurements: bool = False) -> Controlled:
    """Warm-up, then the control window, in the open ``sim`` (steps 3-6 of the module
    docstring); ``cfg`` has the control horizon."""
    from arzsumo.kernel_cache import cached_kernels

    params, period = scenario.params, cfg.control_period
    plant = SumoPlant(sim, params.length, cfg, curve, scenario)
    warm = warm_up(plant, settings.warmup, period, bar)
    plant.timings = dict.fromkeys(plant.timings, 0.0)   # time the control window only
    warmup_meter = {**plant.meter.start_window(), "duration_s": float(warm[-1].t)}
    start = plant.sensor.start_window(warm[-1].t)
    eq = operating_point(settings, scenario.equilibrium, warm, period)
    lin = linearize(eq)
    kernels = (cached_kernels(lin.system, settings.kernel_cells)
               if is_pde(settings.controller) else None)
    estimator, acting = estimation_stage(scenario.estimation, scenario.sensing,
                                         settings.controller, eq, warm[-1].cells.x,
                                         keep_measurements)
    est = scenario.estimation
    warm_fields = estimator.prime(warm[:-1], warm[-1].t)
    shift = (reference_shift(est.reference, warm_fields, eq, est.reference_window, period)
             if is_pde(acting) and est.reference != "equilibrium" and warm_fields else None)
    check_delay(scenario, acting, lin.eigenvalues, "measured" if eq is not scenario.equilibrium
                else "")
    ctrl = compensate(build_controller(acting, lin, kernels, design, settings, cfg,
                                       scenario.alinea), acting, scenario)
    ref_name = settings.controller if is_pde(settings.controller) else "open"
    ref_ctrl = build_controller(ref_name, lin, kernels, design, settings, cfg,
                                scenario.alinea)
    q_nom = curve.outflow_at(cfg.green_share)
    opts = SolverOptions(cells=settings.twin_cells, scheme=settings.twin_scheme,
                         horizon=cfg.horizon, control_period=period)
    twins = TwinPair(eq, lin, warm[-1].cells, opts, settings.smoothing, ref_ctrl, q_nom)
    act = scenario.actuation
    actuator = MeterActuator(plant.meter, q_nom, settings.controller == "open",
                             ActuationLimits.of(act, q_nom, curve, cfg))
    loop = ClosedLoop(plant, estimator, ctrl, actuator, twins, period, act.anti_windup,
                      shift)
    trace = loop.run(warm[-1], cfg.horizon, bar)
    return Controlled(loop, trace, ref_ctrl, eq, q_nom, warmup_meter, start, estimator)
