"""The time loop of the nonlinear twin: CFL-adaptive stepping, controller hook, guard
(docs/twin.md, "Time loop and guard").

:class:`TwinStepper` owns the one time loop (as PyClaw's controller does): it advances the
state with a held outflow q* + U, redoes a step whose waves turned out faster than Courant
1, and stops with :class:`TwinStoppedError` when the state leaves the physical domain,
keeping the last valid state; the SUMO bridge drives it directly. :func:`simulate` runs a
whole experiment on it and returns a :class:`TwinResult`. One step: :mod:`arzsumo.pde.scheme`.
"""

from __future__ import annotations

import logging
import math
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from arzsumo.control.base import Controller, MacroState, OpenLoop
from arzsumo.errors import ArzsumoError, require
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.pde.boundary import Inlet
from arzsumo.pde.flux import FLUXES, LIMITERS
from arzsumo.pde.sampling import Checks, Samples
from arzsumo.pde.scheme import SCHEMES, Transport, max_cell_speed
from arzsumo.pde.state import (
    cell_centres,
    domain_violation,
    macro_state,
    to_conserved,
    to_primitive,
    total_vehicles,
)

log = logging.getLogger(__name__)

#: Largest Courant number accepted after a step before it is redone with a smaller dt.
CFL_MAX = 1.0

StepCallback = Callable[[float, np.ndarray, float, float], None]


class TwinStoppedError(ArzsumoError):
    """The state left the physical domain (or max_steps was reached) at time ``t``."""

    def __init__(self, t: float, reason: str) -> None:
        super().__init__(f"stopped at t = {t:.3f} s: {reason}")
        self.t = t
        self.reason = reason


@dataclass(frozen=True)
class SolverOptions:
    """Numerical and control-loop settings (SI).

    Parameters
    ----------
    cells : int
        Number of finite volumes on [0, L].
    scheme : {"first", "muscl"}
    flux : {"hll", "rusanov"}
        Numerical flux (see :mod:`arzsumo.pde.flux`).
    limiter : {"vanleer", "minmod", "mc"}
        Slope limiter for ``muscl``.
    cfl : float
        Target Courant number max|lambda| dt / dx, in (0, 1].
    horizon : float
        Simulated time T, s.
    control_period : float
        Time between controller checks, s; U is held in between.
    output_period : float
        Time between stored fields, s.
    u_min, u_max : float or None
        Feasible range of U, veh/s; None means -q* and +q* (outflow between 0 and 2 q*).
    max_steps : int
        Safety limit on the number of time steps.
    """

    cells: int = 200
    scheme: str = "first"
    flux: str = "hll"
    limiter: str = "vanleer"
    cfl: float = 0.9
    horizon: float = 450.0
    control_period: float = 1.0
    output_period: float = 1.0
    u_min: float | None = None
    u_max: float | None = None
    max_steps: int = 5_000_000

    def __post_init__(self) -> None:
        require(isinstance(self.cells, int) and self.cells >= 4, "cells", self.cells,
                "an integer >= 4")
        require(self.scheme in SCHEMES, "scheme", self.scheme, f"one of {', '.join(SCHEMES)}")
        require(self.flux in FLUXES, "flux", self.flux, f"one of {', '.join(FLUXES)}")
        require(self.limiter in LIMITERS, "limiter", self.limiter,
                f"one of {', '.join(LIMITERS)}")
        require(0.0 < self.cfl <= CFL_MAX, "cfl", self.cfl, f"a number in (0, {CFL_MAX}]")
        for name in ("horizon", "control_period", "output_period"):
            value = getattr(self, name)
            require(math.isfinite(value) and value > 0, name, value, "a time > 0 s")
        if self.u_min is not None and self.u_max is not None:
            require(self.u_min <= self.u_max, "u_min", self.u_min,
                    f"at most u_max = {self.u_max}")


@dataclass(frozen=True)
class TwinResult:
    """Fields and control history of one twin run. SI units.

    Attributes
    ----------
    t : ndarray (n_t,)
        Output times, s.
    x : ndarray (n_x,)
        Cell centres, m.
    fields : ndarray (n_t, 4, n_x)
        Primitive fields (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) at the output times.
    control_t, control_u, control_u_requested : ndarray (n_checks,)
        Check times (s), applied (saturated) U and the controller's U (veh/s).
    saturated_time : float
        Time (s) during which the requested U lay outside [u_min, u_max].
    inflow, outflow : float
        Vehicles that entered at x = 0 and left at x = L.
    extra : dict
        ``final_state`` (conserved q), ``total_vehicles`` at the end, and
        ``outlet_limited_time`` (s during which the arriving demand, not q* + U, set the
        outflow; see :mod:`arzsumo.pde.boundary`).
    complete : bool
        False when the run stopped early; ``status`` then says where and why.
    """

    equilibrium: Equilibrium
    options: SolverOptions
    controller: Controller
    t: np.ndarray
    x: np.ndarray
    fields: np.ndarray
    control_t: np.ndarray
    control_u: np.ndarray
    control_u_requested: np.ndarray
    saturated_time: float
    u_range: tuple[float, float]
    inflow: float
    outflow: float
    steps: int
    rejected_steps: int
    wall_time: float
    complete: bool
    status: str
    extra: dict = field(default_factory=dict)

    @property
    def dx(self) -> float:
        """Cell width, m."""
        return self.equilibrium.params.length / self.x.size

    @property
    def speed_up(self) -> float:
        """Simulated seconds per wall-clock second."""
        return float(self.t[-1] / self.wall_time) if self.wall_time > 0 else math.inf


class TwinStepper:
    """The twin's state and its time loop; advance it with a held U.

    Parameters
    ----------
    eq : Equilibrium
        Reference equilibrium: q* for the outlet, rho_i* and q* for the default inlet.
    initial : ndarray, shape (4, cells)
        Primitive fields (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) on the cell centres.
    options : SolverOptions, optional
        ``cells``, ``scheme``, ``flux``, ``limiter``, ``cfl``, ``max_steps`` are used here.
    inlet : Inlet, optional
        Default :meth:`Inlet.at_equilibrium` of the linearisation at ``eq``.
    t0 : float
        Initial time, s.

    Attributes
    ----------
    t : float
        Current time, s.
    q : ndarray (4, cells)
        Conserved state (rho_h, y_h, rho_a, y_a); always inside the physical domain.
    inflow, outflow : float
        Vehicles that have entered at x = 0 and left at x = L so far.
    steps, rejected_steps : int
    outlet_limited_time : float
        Seconds during which the arriving demand, not q* + U, set the outflow.
    """

    def __init__(self, eq: Equilibrium, initial: np.ndarray, options: SolverOptions | None = None,
                 inlet: Inlet | None = None, t0: float = 0.0) -> None:
        from arzsumo.model.characteristic import linearize

        self.eq = eq
        self.options = opts = options or SolverOptions()
        self.params = eq.params
        self.x = cell_centres(eq.params.length, opts.cells)
        lin = linearize(eq)
        if lin.regime != "congested":
            log.warning("the equilibrium is in free flow (lambda_4 = %.3g m/s >= 0): the "
                        "boundary conditions of section 2 are posed for congestion; in free "
                        "flow the inlet under-determines and the results are not reliable",
                        lin.eigenvalues[3])
        self.transport = Transport(eq.params, opts.cells, opts.scheme, opts.flux, opts.limiter,
                                   inlet or Inlet.at_equilibrium(lin))
        self.q_star = eq.q
        self.t = float(t0)
        self.inflow = self.outflow = self.outlet_limited_time = 0.0
        self.steps = self.rejected_steps = 0
        self.set_state(initial)

    @property
    def dx(self) -> float:
        """Cell width, m."""
        return self.transport.dx

    def set_state(self, fields: np.ndarray | MacroState) -> None:
        """Replace the state by primitive fields (4, cells) or a :class:`MacroState`.

        Raises :class:`ArzsumoError` naming the variable and position if the fields lie
        outside the physical domain.
        """
        if isinstance(fields, MacroState):
            fields = np.stack([fields.rho_h, fields.v_h, fields.rho_a, fields.v_a])
        fields = np.asarray(fields, float)
        n = self.options.cells
        require(fields.shape == (4, n), "initial", fields.shape,
                f"shape (4, {n}) of (rho_h, v_h, rho_a, v_a) on the cells")
        q = to_conserved(self.params, *fields)
        problem = domain_violation(self.params, q, self.x)
        if problem is not None:
            raise ArzsumoError(f"initial state outside the physical domain: {problem}")
        self.q = q
        self._smax = max_cell_speed(self.params, q)

    def macro_state(self) -> MacroState:
        """The current fields as handed to controllers."""
        return macro_state(self.params, self.t, self.x, self.q)

    def primitive(self) -> np.ndarray:
        """Current (rho_h, v_h, rho_a, v_a), shape (4, cells)."""
        return to_primitive(self.params, self.q)

    def total_vehicles(self) -> float:
        """Vehicles on the road now."""
        return total_vehicles(self.q, self.dx)

    def advance(self, t_end: float, u: float, callback: StepCallback | None = None) -> None:
        """Advance to ``t_end`` (s) with outlet flow q* + ``u`` (veh/s) held.

        Raises
        ------
        TwinStoppedError
            If a step would leave the physical domain, the inlet condition has no
            solution, or ``max_steps`` is reached; the state stays the last valid one.
        """
        opts, tr, p = self.options, self.transport, self.params
        eps = 1e-12 * max(1.0, abs(t_end))
        outflow = self.q_star + float(u)
        with np.errstate(all="ignore"):
            while self.t < t_end - eps:
                if self.steps >= opts.max_steps:
                    raise TwinStoppedError(self.t, f"max_steps = {opts.max_steps} reached")
                dt = min(opts.cfl * tr.dx / max(self._smax, 1e-12), t_end - self.t)
                while True:
                    try:
                        q_new, s_step, din, dout = tr.step(self.q, self.t, dt, outflow)
                    except ArzsumoError as exc:
                        raise TwinStoppedError(self.t, str(exc)) from None
                    if s_step * dt <= CFL_MAX * tr.dx * (1 + 1e-12) or dt < 1e-9:
                        break
                    self.rejected_steps += 1         # waves sped up during the step: redo
                    dt = opts.cfl * tr.dx / s_step
                self._smax = s_step
                problem = domain_violation(p, q_new, self.x)
                if problem is not None:
                    raise TwinStoppedError(self.t + dt, problem)
                if tr.limited:
                    self.outlet_limited_time += dt
                self.q = q_new
                self.t = t_end if abs(self.t + dt - t_end) <= eps else self.t + dt
                self.inflow += din
                self.outflow += dout
                self.steps += 1
                if callback is not None:
                    callback(self.t, self.q, din, dout)


def simulate(eq: Equilibrium, initial: np.ndarray, *, controller: Controller | None = None,
             options: SolverOptions | None = None, inlet: Inlet | None = None,
             callback: StepCallback | None = None) -> TwinResult:
    """Run the nonlinear twin from primitive ``initial`` fields under ``controller``.

    Parameters
    ----------
    eq, initial, options, inlet
        As for :class:`TwinStepper` (``initial``: e.g.
        :func:`arzsumo.pde.initial.initial_fields`).
    controller : Controller, optional
        Reset, then checked once per control period via :meth:`Controller.check`
        (first check at t = 0); its U is held until the next check. Default open loop.
    callback : callable, optional
        ``callback(t, q, vehicles_in, vehicles_out)`` after every accepted step with the
        conserved state and the vehicles that crossed each boundary during the step.

    Returns
    -------
    TwinResult
        ``complete`` is False if the state left the physical domain; ``status`` names the
        time, position and variable.
    """
    opts = options or SolverOptions()
    ctrl = controller if controller is not None else OpenLoop()
    ctrl.reset()
    stepper = TwinStepper(eq, initial, opts, inlet)
    q_star = stepper.q_star
    bounds = (-q_star if opts.u_min is None else opts.u_min,
              q_star if opts.u_max is None else opts.u_max)
    checks = Checks(ctrl, opts.control_period, opts.horizon, bounds)
    samples = Samples(opts.horizon, opts.output_period, opts.cells)
    start = _time.perf_counter()
    status = _time_loop(stepper, checks, samples, opts, callback)
    wall = _time.perf_counter() - start
    complete = status == "completed"
    if not complete:
        log.warning("twin run incomplete: %s", status)
        if samples.k == 0 or samples.t[samples.k - 1] < stepper.t:
            samples.take(stepper.t, stepper.primitive())   # the last valid state
    return TwinResult(eq, opts, ctrl, samples.t[:samples.k].copy(), stepper.x,
                      samples.f[:samples.k].copy(), np.asarray(checks.t),
                      np.asarray(checks.u), np.asarray(checks.requested), checks.saturated,
                      checks.bounds, stepper.inflow, stepper.outflow, stepper.steps,
                      stepper.rejected_steps, wall, complete, status,
                      {"final_state": stepper.q, "total_vehicles": stepper.total_vehicles(),
                       "outlet_limited_time": stepper.outlet_limited_time})


def _time_loop(stepper: TwinStepper, checks: Checks, samples: Samples,
               opts: SolverOptions, callback: StepCallback | None) -> str:
    """Advance to the horizon between output samples and checks; return the status."""
    eps = 1e-9 * max(1.0, opts.horizon)
    while True:
        t = stepper.t
        if samples.due(t, eps):
            samples.take(t, stepper.primitive())
        if t >= opts.horizon - eps:
            return "completed"
        if checks.due(t, eps):
            checks.check(t, stepper.macro_state())
        t_next = min(checks.k * opts.control_period, samples.k * opts.output_period,
                     opts.horizon)
        try:
            stepper.advance(t_next, checks.held, callback)
        except TwinStoppedError as exc:
            return str(exc)
