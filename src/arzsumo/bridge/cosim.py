"""The co-simulation loop: SUMO, the controller, the ramp meter, and two PDE twins.

Sequence (``arzsumo run``):

1. Check the scenario: a PDE controller needs a congested equilibrium (lambda_4 < 0); with
   ``equilibrium = "scenario"`` this is refused before SUMO starts.
2. Start SUMO; reach the operating point by a warm-up under the nominal meter (or place
   vehicles from the scenario's ``[initial]`` profile).
3. With ``equilibrium = "measured"``, take the mean Edie densities of the last 60 s of the
   warm-up as the equilibrium of the (calibrated) model, and check its regime.
4. Solve (or load) the kernels; start both twins from the aggregated microscopic state.
5. Every control period: aggregate the micro state (Edie, per class and cell), check the
   controller, command the meter with q_nom + U, where q_nom is the mainline outflow of
   the nominal plan on the meter's calibrated curve (so U = 0 is the open loop);
   advance the *replay* twin with the inflow and the outflow SUMO produced (model
   fidelity) and the *reference* twin in its own closed loop (what the design promised).
   SUMO's outflow counts whole vehicles per period; the replay uses it smoothed with
   the same time constant as the inlet (``smoothing_s``), which keeps the vehicle count.

The meter's counts (plan and light changes, queue maximum) cover the control window only:
the meter's window is closed at the start of control and the warm-up's counts are kept
apart (``CoSimResult.warmup_meter``).

Both twins take the measured state of SUMO's first cell, smoothed exponentially, as their
boundary state at x = 0 (a ghost cell): their inflow follows the measured inflow.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arzsumo.bridge.config import RunSettings
from arzsumo.control.alinea import Alinea
from arzsumo.control.base import Controller, MacroState, OpenLoop
from arzsumo.control.etc import EtcDesign
from arzsumo.control.registry import PDE_CONTROLLERS, make_controller
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.model.characteristic import Linearization, linearize
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import area_occupancy, equilibrium_speeds
from arzsumo.model.params import ModelParameters
from arzsumo.progress import Progress
from arzsumo.scenarios import Scenario
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.measure import CellData, MainlineSensor
from arzsumo.sumo.meter import DEFAULT_CURVE, GreenShareCurve, RampMeter
from arzsumo.sumo.network import DOWN
from arzsumo.sumo.simulation import RunReport, open_simulation
from arzsumo.twin.boundary import Inlet
from arzsumo.twin.solver import SolverOptions, TwinStepper, TwinStoppedError

log = logging.getLogger(__name__)

#: seconds of warm-up averaged for a measured equilibrium (and ALINEA's target occupancy)
MEASURE_WINDOW = 60.0
#: ALINEA target when the warm-up measured no downstream occupancy (fraction)
DEFAULT_OCCUPANCY_TARGET = 0.2


def check_before_start(settings: RunSettings, eq: Equilibrium) -> Linearization:
    """Refuse a PDE controller at a free-flow equilibrium (lambda_4 >= 0), before SUMO runs."""
    lin = linearize(eq)
    if settings.controller in PDE_CONTROLLERS and lin.regime != "congested":
        raise ScenarioError(
            f"controller = {settings.controller!r} is not allowed at this equilibrium: "
            f"lambda_4 = {lin.eigenvalues[3] * 3.6:.2f} km/h >= 0 (free flow); PDE "
            "boundary control needs congestion (lambda_4 < 0); use 'open' or 'alinea'")
    return lin


def fill_speeds(params: ModelParameters, rho_h: np.ndarray, v_h: np.ndarray,
                rho_a: np.ndarray, v_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Speeds with empty cells (NaN) replaced by the fundamental diagram's Ve at the cell."""
    ve_h, ve_a = equilibrium_speeds(params, rho_h, rho_a)
    return np.where(np.isfinite(v_h), v_h, ve_h), np.where(np.isfinite(v_a), v_a, ve_a)


def to_twin_grid(params: ModelParameters, data: CellData, x_twin: np.ndarray,
                 ao_limit: float = 0.9) -> tuple[np.ndarray, float]:
    """Micro cell data interpolated to the twin's cells, made admissible for the model.

    Densities are scaled down where the calibrated model could not hold them (AO above
    ``ao_limit`` of its maximum); returns the fields (4, n) and the vehicles removed (veh).
    """
    v_h, v_a = fill_speeds(params, data.rho_h, data.v_h, data.rho_a, data.v_a)
    rho_h = np.interp(x_twin, data.x, data.rho_h)
    rho_a = np.interp(x_twin, data.x, data.rho_a)
    rho_h = np.maximum(rho_h, 1e-4)
    rho_a = np.maximum(rho_a, 1e-4)
    ao = area_occupancy(params, rho_h, rho_a)
    scale = np.minimum(1.0, ao_limit * params.ao_max / ao)
    dx = x_twin[1] - x_twin[0]
    removed = float(np.sum((rho_h + rho_a) * (1 - scale)) * dx)
    rho_h, rho_a = rho_h * scale, rho_a * scale
    fields = np.vstack([rho_h, np.interp(x_twin, data.x, v_h), rho_a,
                        np.interp(x_twin, data.x, v_a)])
    return fields, removed


class _InletState:
    """Mutable holder of the smoothed inlet state (rho_h, v_h, rho_a, v_a), SI."""

    def __init__(self, values: np.ndarray) -> None:
        self.values = np.array(values, float)


@dataclass(frozen=True)
class _GhostInlet(Inlet):
    """An inlet whose boundary state is the measured one (a ghost cell), not the l4 solve.

    SUMO's first cell is far from the model's equilibrium at times (AVs crawl while HVs
    pass); the paper's inlet condition, linear in the outgoing Riemann variable, can then
    give negative boundary speeds. The measured state, smoothed, is always admissible.
    """

    holder: _InletState | None = None

    def boundary_primitive(self, t: float, z0: np.ndarray) -> np.ndarray:
        assert self.holder is not None
        return self.holder.values


class MeasuredInlet:
    """Exponentially smoothed inlet state measured in SUMO's first cell, for the twins.

    The densities and speeds of the first micro cell (and, where a class is absent, its
    equilibrium speed) are smoothed with time constant ``tau``; the twins' boundary state at
    x = 0 is that smoothed state, so their inflow follows SUMO's.
    """

    def __init__(self, eq: Equilibrium, lin: Linearization, tau: float) -> None:
        self.params, self.tau = eq.params, tau
        self.state = _InletState(np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a]))
        self.inlet = _GhostInlet(eq.rho_h, eq.rho_a, eq.q, lin.T[3], self.state)

    def update(self, data: CellData, dt: float) -> None:
        a = 1.0 - math.exp(-dt / self.tau)
        v_h, v_a = fill_speeds(self.params, data.rho_h[:1], data.v_h[:1], data.rho_a[:1],
                               data.v_a[:1])
        new = np.array([max(data.rho_h[0], 1e-4), v_h[0], max(data.rho_a[0], 1e-4), v_a[0]])
        self.state.values = self.state.values + a * (new - self.state.values)

    def start(self, data: CellData) -> None:
        """Start from the measured first cell (no smoothing history)."""
        self.state.values = self.state.values * 0
        self.update(data, 1e9)

@dataclass
class Twin:
    """One twin run alongside SUMO.

    When a step would leave the model's physical domain (SUMO can hold area occupancies the
    calibrated fundamental diagram cannot), the twin is re-synchronised to the aggregated
    micro state of that period and goes on; every re-synchronisation is counted, and the
    period it happens in is excluded from the fidelity measures (NaN fields).
    """

    mode: str
    stepper: TwinStepper
    controller: Controller | None = None
    resyncs: list[float] = field(default_factory=list)
    reasons: list[str] = field(default_factory=list)
    _fresh: bool = False

    def advance(self, t: float, u: float, resync: Callable[[], np.ndarray]) -> None:
        self._fresh = False
        try:
            self.stepper.advance(t, u)
        except TwinStoppedError as exc:
            self.resyncs.append(t)
            self.reasons.append(str(exc))
            log.debug("%s twin re-synchronised at t = %.1f s: %s", self.mode, t, exc)
            self.stepper.set_state(resync())
            self.stepper.t = t
            self._fresh = True

    def sample(self, x: np.ndarray) -> np.ndarray:
        """Fields at positions x (4, len(x)); NaN in a period that ended in a re-sync."""
        if self._fresh:
            return np.full((4, x.size), np.nan)
        f = self.stepper.primitive()
        return np.vstack([np.interp(x, self.stepper.x, row) for row in f])


@dataclass
class CoSimResult:
    """Everything a run produced; arrays are per control period (SI, times from control start)."""

    scenario: Scenario
    settings: RunSettings
    sumo: SumoConfig
    equilibrium: Equilibrium
    q_nominal: float
    t: np.ndarray
    x: np.ndarray
    micro: np.ndarray                  # (periods, 4, cells)
    replay: np.ndarray
    reference: np.ndarray
    periods: dict[str, np.ndarray]     # per-period columns
    controller_log: Any
    reference_log: Any
    meter: dict[str, float]
    report: RunReport | None
    twin_status: dict[str, Any]
    placement: str
    wall_time: float
    timings: dict[str, float]
    #: meter counts from t = 0 to the start of control, and that time (``duration_s``, s)
    warmup_meter: dict[str, float] = field(default_factory=dict)


def _controller(name: str, lin: Linearization, kernels: Any, design: EtcDesign,
                settings: RunSettings, curve: GreenShareCurve, cfg: SumoConfig,
                alinea_target: float) -> Controller:
    if name == "open":
        return OpenLoop()
    if name == "alinea":
        return Alinea(curve.outflow_at, cfg.green_share, alinea_target, settings.alinea_gain,
                      settings.alinea_saturation, cfg.green_share_min, cfg.green_share_max)
    return make_controller(name, lin, kernels, design)


def run_cosimulation(scenario: Scenario, settings: RunSettings, cfg: SumoConfig,
                     design: EtcDesign, *, initial_fields: np.ndarray | None = None,
                     curve: GreenShareCurve = DEFAULT_CURVE, progress: bool = False,
                     on_period: Any = None) -> CoSimResult:
    """Run SUMO with the controller of ``settings`` and both twins; see the module docstring.

    ``initial_fields`` (4, cells on the micro grid) places vehicles at t = 0 when
    ``settings.start == "placement"``.
    """
    from arzsumo.kernel_cache import cached_kernels
    from arzsumo.sumo.placement import place_vehicles

    wall0 = time.perf_counter()
    params = scenario.params
    eq = scenario.equilibrium
    if settings.equilibrium == "scenario":
        check_before_start(settings, eq)
    total = settings.warmup + cfg.horizon
    run_cfg = cfg.with_(horizon=total)
    initial: list = []
    placement = "none"
    if settings.start == "placement":
        if initial_fields is None:
            raise ScenarioError("start = 'placement' needs an [initial] profile")
        n = initial_fields.shape[1]
        xc = (np.arange(n) + 0.5) * params.length / n
        initial, rep = place_vehicles(params, run_cfg, xc, *initial_fields)
        placement = rep.summary()
    timings = {"sumo_step": 0.0, "measure_actuate": 0.0, "controller": 0.0, "twins": 0.0}
    bar = Progress(total, f"{settings.controller} seed {cfg.seed}", enabled=progress)
    with open_simulation(params, run_cfg, initial=initial) as sim:
        lib = sim.lib
        meter = RampMeter(lib, run_cfg, curve)
        sensor = MainlineSensor(lib, params.length, cfg.cell_length, cfg.step_length,
                                cfg.steps_per_period)
        occ_lane = f"{DOWN}_0"
        warm: list[CellData] = []
        occ_acc, occ_n = 0.0, 0
        occ_warm: list[float] = []
        data: CellData | None = None
        while sim.time < settings.warmup - 1e-9:
            t = sim.step()
            meter.step()
            occ_acc += lib.lane.getLastStepOccupancy(occ_lane)
            occ_n += 1
            got = sensor.collect(t)
            if got is not None:
                data = got
                warm.append(got)
                occ_warm.append(occ_acc / occ_n)
                occ_acc, occ_n = 0.0, 0
            bar.update(t)
        if settings.equilibrium == "measured":
            k = max(1, round(MEASURE_WINDOW / cfg.control_period))
            rho_h = float(np.mean([w.rho_h.mean() for w in warm[-k:]]))
            rho_a = float(np.mean([w.rho_a.mean() for w in warm[-k:]]))
            try:
                eq = Equilibrium(params, rho_h, rho_a)
            except ArzsumoError as exc:
                raise ScenarioError(f"the measured operating point is not an admissible "
                                    f"equilibrium of the model: {exc}") from None
            check_before_start(settings, eq)
        lin = linearize(eq)
        kernels = (cached_kernels(lin.system, settings.kernel_cells)
                   if settings.controller in PDE_CONTROLLERS else None)
        k_occ = max(1, round(MEASURE_WINDOW / cfg.control_period))
        occ_target = settings.alinea_target or (float(np.mean(occ_warm[-k_occ:]))
                                                if occ_warm else 0.0)
        if occ_target <= 0.01:     # nothing reached the detector during a short warm-up
            occ_target = DEFAULT_OCCUPANCY_TARGET
            if settings.controller == "alinea":
                log.warning("no downstream occupancy measured in the warm-up; ALINEA target "
                            "%.2f", occ_target)
        ctrl = _controller(settings.controller, lin, kernels, design, settings, curve, cfg,
                           occ_target)
        ref_name = settings.controller if settings.controller in PDE_CONTROLLERS else "open"
        ref_ctrl = _controller(ref_name, lin, kernels, design, settings, curve, cfg, occ_target)
        ctrl.reset()
        ref_ctrl.reset()
        q_nom = curve.outflow_at(cfg.green_share)
        if data is None:          # no warm-up: one period of SUMO to measure from
            while data is None:
                t = sim.step()
                meter.step()
                data = sensor.collect(t)
        t0 = data.t
        warmup_meter = {**meter.start_window(), "duration_s": float(t0)}
        opts = SolverOptions(cells=settings.twin_cells, scheme=settings.twin_scheme,
                             horizon=cfg.horizon, control_period=cfg.control_period)
        inlet = MeasuredInlet(eq, lin, settings.smoothing)
        inlet.start(data)
        q_out = q_nom         # smoothed outflow replayed at x = L, from the nominal plan's
        x_twin = (np.arange(settings.twin_cells) + 0.5) * params.length / settings.twin_cells
        start_fields, removed = to_twin_grid(params, data, x_twin)
        if removed > 0.5:
            log.info("twin start: %.1f vehicles removed where the model cannot hold them",
                     removed)
        twins = {mode: Twin(mode, TwinStepper(eq, start_fields, opts, inlet.inlet, t0=0.0))
                 for mode in ("replay", "reference")}
        twins["reference"].controller = ref_ctrl
        rows: dict[str, list[float]] = {k: [] for k in (
            "t", "u", "u_continuous", "triggered", "green_commanded", "green_running",
            "light_changes", "plan_changes", "queue", "max_queue", "inflow_h", "inflow_a",
            "outflow_h", "outflow_a", "occupancy_out", "u_reference", "controller_s")}
        micro, replay, reference, times = [], [], [], []
        xm = data.x

        def macro(d: CellData, t_rel: float, occ: float) -> MacroState:
            v_h, v_a = fill_speeds(params, d.rho_h, d.v_h, d.rho_a, d.v_a)
            return MacroState(t_rel, d.x, d.rho_h, v_h, d.rho_a, v_a, occ)

        occ = occ_warm[-1] if occ_warm else float("nan")
        state = macro(data, 0.0, occ)
        while True:
            t_rel = data.t - t0
            c0 = time.perf_counter()
            u = ctrl.check(state)
            c1 = time.perf_counter()
            timings["controller"] += c1 - c0
            u_ref = ref_ctrl.check(twins["reference"].stepper.macro_state())
            timings["twins"] += time.perf_counter() - c1
            final = t_rel >= cfg.horizon - 1e-9
            # no period follows the last check: a command there would count a plan change
            # that never runs
            green = (meter.command_outflow(q_nom + u)
                     if settings.controller != "open" and not final else meter.green_share)
            last = ctrl.log
            rows["t"].append(t_rel)
            rows["u"].append(u)
            rows["u_continuous"].append(last.u_continuous[-1] if last.u_continuous else u)
            rows["triggered"].append(float(last.triggered[-1]) if last.triggered else 0.0)
            rows["green_commanded"].append(green)
            rows["u_reference"].append(u_ref)
            rows["controller_s"].append(c1 - c0)
            if final:
                for key in ("green_running", "light_changes", "plan_changes", "queue",
                            "max_queue", "inflow_h", "inflow_a", "outflow_h", "outflow_a",
                            "occupancy_out"):
                    rows[key].append(np.nan)
                break
            # one control period of SUMO with the new command
            s0 = time.perf_counter()
            occ_acc, occ_n, got = 0.0, 0, None
            while got is None:
                t = sim.step()
                s1 = time.perf_counter()
                meter.step()
                occ_acc += lib.lane.getLastStepOccupancy(occ_lane)
                occ_n += 1
                got = sensor.collect(t)
                timings["measure_actuate"] += time.perf_counter() - s1
            timings["sumo_step"] += time.perf_counter() - s0
            data, occ = got, occ_acc / occ_n
            tw0 = time.perf_counter()
            inlet.update(data, cfg.control_period)
            t_next = data.t - t0
            q_out += (1.0 - math.exp(-cfg.control_period / settings.smoothing)) * (
                data.outflow_h + data.outflow_a - q_out)
            def resync(d: CellData = data) -> np.ndarray:
                return to_twin_grid(params, d, x_twin)[0]

            twins["replay"].advance(t_next, q_out - eq.q, resync)
            twins["reference"].advance(t_next, u_ref, resync)
            timings["twins"] += time.perf_counter() - tw0
            for key, value in (("green_running", meter.green_share),
                               ("light_changes", meter.light_changes),
                               ("plan_changes", meter.plan_changes), ("queue", meter.queue),
                               ("max_queue", meter.max_queue), ("inflow_h", data.inflow_h),
                               ("inflow_a", data.inflow_a), ("outflow_h", data.outflow_h),
                               ("outflow_a", data.outflow_a), ("occupancy_out", occ)):
                rows[key].append(float(value))
            state = macro(data, t_next, occ)
            times.append(t_next)
            micro.append(np.vstack([data.rho_h, data.v_h, data.rho_a, data.v_a]))
            replay.append(twins["replay"].sample(xm))
            reference.append(twins["reference"].sample(xm))
            bar.update(data.t)
            if on_period is not None:
                on_period(t_next)
        meter_summary = meter.summary()
    bar.close()
    # the row of the last check has no following period: drop it from per-period columns
    periods = {k: np.asarray(v[:len(times)], float) for k, v in rows.items()}
    status = {mode: {"resyncs": len(tw.resyncs), "first_resync_s": (tw.resyncs[0] if tw.resyncs
                                                                  else None),
                     "first_reason": tw.reasons[0] if tw.reasons else ""}
              for mode, tw in twins.items()}
    timings["sumo_step"] -= timings["measure_actuate"]
    return CoSimResult(scenario, settings, cfg, eq, q_nom, np.asarray(times), xm,
                       np.asarray(micro), np.asarray(replay), np.asarray(reference), periods,
                       ctrl.log, ref_ctrl.log, meter_summary, sim.report, status, placement,
                       time.perf_counter() - wall0, timings, warmup_meter)
