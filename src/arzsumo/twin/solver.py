"""The time loop of the nonlinear twin: finite volumes, CFL-adaptive step, controller hook.

One function, :func:`simulate`, owns the loop (as PyClaw's controller does): it picks the
time step from the CFL condition, lands exactly on control checks and output instants,
calls the controller once per control period through :meth:`Controller.check` and holds
its U in between, saturates U to a feasible range (and counts the time spent saturated),
and stops with a message when the state leaves the physical domain, keeping the results
so far (``complete=False``).

Each step is Strang-split: exact relaxation over dt/2 (:mod:`arzsumo.twin.source`), one
transport step, relaxation over dt/2. Transport is either

* ``first``: forward Euler with the numerical flux of :mod:`arzsumo.twin.flux` between
  cell averages (first order, the paper's Algorithm 1 with a proper upwind flux), or
* ``muscl``: limited linear reconstruction of (rho, v - Ve) with SSP-RK2 (Heun) in time
  (second order on smooth solutions).

Boundary fluxes come from :mod:`arzsumo.twin.boundary`. Everything is vectorised over
cells; the only Python loop is over time steps.
"""

from __future__ import annotations

import logging
import math
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from arzsumo.control.base import Controller, OpenLoop
from arzsumo.errors import ArzsumoError, require
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import speed_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.twin.boundary import Inlet, outlet_flux
from arzsumo.twin.flux import (
    FLUXES,
    LIMITERS,
    from_reconstruction,
    waves,
)
from arzsumo.twin.source import relax
from arzsumo.twin.state import (
    RHO_A,
    RHO_H,
    Y_A,
    Y_H,
    cell_centres,
    domain_violation,
    macro_state,
    to_conserved,
    to_primitive,
    total_vehicles,
)

log = logging.getLogger(__name__)

SCHEMES = ("first", "muscl")
#: Largest Courant number accepted after a step before it is redone with a smaller dt.
CFL_MAX = 1.0


@dataclass(frozen=True)
class SolverOptions:
    """Numerical and control-loop settings (SI).

    Parameters
    ----------
    cells : int
        Number of finite volumes on [0, L].
    scheme : {"first", "muscl"}
    flux : {"hll", "rusanov"}
        Numerical flux (see :mod:`arzsumo.twin.flux`).
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
        outflow; see :mod:`arzsumo.twin.boundary`).
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


StepCallback = Callable[[float, np.ndarray, float, float], None]


class _Transport:
    """Right-hand side -(F_{j+1/2} - F_{j-1/2}) / dx with the boundary fluxes."""

    def __init__(self, eq: Equilibrium, opts: SolverOptions, inlet: Inlet) -> None:
        self.p = eq.params
        self.eq = eq
        self.dx = self.p.length / opts.cells
        self.riemann = FLUXES[opts.flux]
        self.limiter = LIMITERS[opts.limiter]
        self.second = opts.scheme == "muscl"
        self.inlet = inlet
        self.limited = False        # outlet demand-limited at the last evaluation
        n = opts.cells
        self._pad = np.empty((4, n + 2))
        self._faces = np.empty((4, 2 * n))
        self._full = np.empty((4, n + 1))

    def _primitive_at(self, r: np.ndarray, j: int) -> np.ndarray:
        """(rho_h, v_h, rho_a, v_a) of cell ``j`` from reconstruction variables ``r``."""
        p = self.p
        rho_h, rho_a = float(r[0, j]), float(r[2, j])
        ve_h, ve_a = speed_of_ao(p, (p.area_h * rho_h + p.area_a * rho_a) / p.road_width)
        return np.array([rho_h, float(r[1, j]) + float(ve_h), rho_a, float(r[3, j]) + float(ve_a)])

    def rhs(self, q: np.ndarray, t: float, outflow: float) -> tuple[np.ndarray, float,
                                                                      float, float]:
        """dq/dt, the largest wave speed (m/s) and the density fluxes in and out (veh/s)."""
        p = self.p
        if self.second:
            n = q.shape[1]
            pad = self._pad                          # (rho_h, w_h, rho_a, w_a) + 2 ghosts
            r = pad[:, 1:-1]
            r[...] = q
            r[Y_H] /= q[RHO_H]
            r[Y_A] /= q[RHO_A]
            # second-order value at x = 0 for the outgoing family: linear extrapolation
            z_b = 1.5 * self._primitive_at(r, 0) - 0.5 * self._primitive_at(r, 1)
            f_in, qb = self.inlet.boundary_flux(p, t, z_b)
            rb = np.array([qb[0], qb[1] / qb[0], qb[2], qb[3] / qb[2]])
            pad[:, 0] = 2.0 * rb - r[:, 0]
            pad[:, -1] = 2.0 * r[:, -1] - r[:, -2]
            d = np.diff(pad, axis=1)
            half = 0.5 * self.limiter(d[:, :-1], d[:, 1:])
            rec = self._faces                        # east faces, then west faces
            np.add(r, half, out=rec[:, :n])
            np.subtract(r, half, out=rec[:, n:])
            faces = waves(p, from_reconstruction(rec))
            flux, smax = self.riemann(faces.sel(slice(0, n - 1)), faces.sel(slice(n + 1, None)))
            out = faces.sel(slice(n - 1, n))
            s = max(float(smax.max()), float(-faces.lo[n]), float(faces.hi[n - 1]))
        else:
            cells = waves(p, q)
            z0 = np.array([q[RHO_H, 0], cells.v_h[0], q[RHO_A, 0], cells.v_a[0]])
            f_in, _ = self.inlet.boundary_flux(p, t, z0)
            flux, smax = self.riemann(cells.sel(slice(None, -1)), cells.sel(slice(1, None)))
            out = cells.sel(slice(-1, None))
            s = max(float(smax.max()), float(-cells.lo[0]), float(cells.hi[-1]))
        f_out, self.limited = outlet_flux(out.q[:, 0], float(out.v_h[0]), float(out.v_a[0]),
                                          outflow, congested=bool(out.lo[0] < 0.0))
        full = self._full
        full[:, 0] = f_in
        full[:, 1:-1] = flux
        full[:, -1] = f_out
        dq = (full[:, :-1] - full[:, 1:]) / self.dx
        return dq, s, float(f_in[RHO_H] + f_in[RHO_A]), float(f_out[RHO_H] + f_out[RHO_A])

    def step(self, q: np.ndarray, t: float, dt: float, outflow: float) -> tuple[np.ndarray,
                                                                                float, float,
                                                                                float]:
        """One Strang-split step: relaxation dt/2, transport dt, relaxation dt/2.

        Returns the new q, the largest wave speed met (m/s) and the vehicles that entered
        and left during the step.
        """
        q = relax(self.p, q, 0.5 * dt)
        dq, s1, fin1, fout1 = self.rhs(q, t, outflow)
        q1 = q + dt * dq
        if not self.second:
            return relax(self.p, q1, 0.5 * dt), s1, dt * fin1, dt * fout1
        dq2, s2, fin2, fout2 = self.rhs(q1, t + dt, outflow)
        q2 = 0.5 * (q + q1 + dt * dq2)
        return (relax(self.p, q2, 0.5 * dt), max(s1, s2), 0.5 * dt * (fin1 + fin2),
                0.5 * dt * (fout1 + fout2))


def _max_cell_speed(p: ModelParameters, q: np.ndarray) -> float:
    w = waves(p, q)
    return float(max(-w.lo.min(), w.hi.max()))


def simulate(eq: Equilibrium, initial: np.ndarray, *, controller: Controller | None = None,
             options: SolverOptions | None = None, inlet: Inlet | None = None,
             callback: StepCallback | None = None) -> TwinResult:
    """Run the nonlinear twin from primitive ``initial`` fields under ``controller``.

    Parameters
    ----------
    eq : Equilibrium
        Reference equilibrium: q* for the outlet, rho_i* and q* for the default inlet.
    initial : ndarray, shape (4, cells)
        (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) on the cell centres
        (see :func:`arzsumo.twin.initial.initial_fields`).
    controller : Controller, optional
        Reset, then checked once per control period via :meth:`Controller.check`
        (first check at t = 0); default open loop.
    options : SolverOptions, optional
    inlet : Inlet, optional
        Default :meth:`Inlet.at_equilibrium` of the linearisation at ``eq``.
    callback : callable, optional
        ``callback(t, q, vehicles_in, vehicles_out)`` after every accepted step with the
        conserved state and the vehicles that crossed each boundary during the step.

    Returns
    -------
    TwinResult
        ``complete`` is False if the state left the physical domain; ``status`` names the
        time, position and variable.
    """
    from arzsumo.model.characteristic import linearize

    opts = options or SolverOptions()
    ctrl = controller if controller is not None else OpenLoop()
    ctrl.reset()
    p = eq.params
    x = cell_centres(p.length, opts.cells)
    initial = np.asarray(initial, float)
    require(initial.shape == (4, opts.cells), "initial", initial.shape,
            f"shape (4, {opts.cells}) of (rho_h, v_h, rho_a, v_a) on the cells")
    q = to_conserved(p, *initial)
    problem = domain_violation(p, q, x)
    if problem is not None:
        raise ArzsumoError(f"initial state outside the physical domain: {problem}")
    transport = _Transport(eq, opts, inlet or Inlet.at_equilibrium(linearize(eq)))
    q_star = eq.q
    u_lo = -q_star if opts.u_min is None else opts.u_min
    u_hi = q_star if opts.u_max is None else opts.u_max

    n_out = math.floor(opts.horizon / opts.output_period + 1e-9) + 1
    out_t = np.empty(n_out)
    out_f = np.empty((n_out, 4, opts.cells))
    ctl_t: list[float] = []
    ctl_u: list[float] = []
    ctl_req: list[float] = []
    k_ctl = k_out = steps = rejected = 0
    t, u, saturated, vin, vout, limited_time = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    status, complete = "completed", True
    smax = _max_cell_speed(p, q)
    start = _time.perf_counter()
    eps = 1e-9 * max(1.0, opts.horizon)
    with np.errstate(all="ignore"):
        while True:
            if k_out < n_out and t >= k_out * opts.output_period - eps:
                out_t[k_out], out_f[k_out] = t, to_primitive(p, q)
                k_out += 1
            if t >= opts.horizon - eps:
                break
            if t >= k_ctl * opts.control_period - eps:
                requested = float(ctrl.check(macro_state(p, t, x, q)))
                u = min(max(requested, u_lo), u_hi)
                if u != requested:
                    saturated += min(opts.control_period, opts.horizon - t)
                ctl_t.append(t)
                ctl_u.append(u)
                ctl_req.append(requested)
                k_ctl += 1
            if steps >= opts.max_steps:
                status, complete = f"stopped at t = {t:.3f} s: max_steps = {opts.max_steps}", False
                break
            t_next = min(k_ctl * opts.control_period, k_out * opts.output_period, opts.horizon)
            dt = min(opts.cfl * transport.dx / max(smax, 1e-12), t_next - t)
            while True:
                try:
                    q_new, s_step, din, dout = transport.step(q, t, dt, q_star + u)
                except ArzsumoError as exc:
                    status, complete = f"stopped at t = {t:.3f} s: {exc}", False
                    break
                if s_step * dt <= CFL_MAX * transport.dx * (1 + 1e-12) or dt < 1e-9:
                    break
                rejected += 1                    # waves sped up during the step: redo it
                dt = opts.cfl * transport.dx / s_step
            if not complete:
                break
            smax = s_step
            if transport.limited:
                limited_time += dt
            problem = domain_violation(p, q_new, x)
            if problem is not None:
                status = f"stopped at t = {t + dt:.3f} s: {problem}"
                complete = False
                break
            q, t = q_new, t + dt
            if abs(t - t_next) <= eps:
                t = t_next
            vin, vout, steps = vin + din, vout + dout, steps + 1
            if callback is not None:
                callback(t, q, din, dout)
    wall = _time.perf_counter() - start
    if not complete:
        log.warning("twin run incomplete: %s", status)
        if k_out == 0 or out_t[k_out - 1] < t:
            out_t[k_out], out_f[k_out] = t, to_primitive(p, q)    # last valid state
            k_out += 1
    return TwinResult(eq, opts, ctrl, out_t[:k_out].copy(), x, out_f[:k_out].copy(),
                      np.asarray(ctl_t), np.asarray(ctl_u), np.asarray(ctl_req), saturated,
                      (u_lo, u_hi), vin, vout, steps, rejected, wall, complete, status,
                      {"final_state": q, "total_vehicles": total_vehicles(q, transport.dx),
                       "outlet_limited_time": limited_time})
