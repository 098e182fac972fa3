"""The replay twin: the nonlinear twin driven by a run's boundary data, sampled like the run.

:func:`run_replay` starts a :class:`arzsumo.pde.TwinStepper` from the data's initial
state (interpolated to the twin grid), holds the inlet ghost cell at ``data.inlet[k]``
and the outlet flow at ``data.outflow[k]`` during period k, and samples the primitive
fields at ``data.x`` at every period end: the SUMO closed loop's replay twin, with the
boundary data given up front. The inlet flux (``ReplayOptions.inlet``: the ghost's, or
bounded by the cell transmission model's supply and demand): ``docs/identify.md``, 'The
inlet'.

Outlet. The twin's outlet carries q* + U, q* the flow of its reference equilibrium: the
uniform equilibrium at the spatial means of the initial densities (always admissible,
AO being linear in the densities). U_k = outflow_k - q*, so the metered outlet flow is
``outflow_k`` whatever the parameters. The ghost-cell inlet replaces the paper's l4
inlet condition, so the replay is posed in free flow as in congestion.

Admissibility. A smaller AO_max may not hold a state the data holds: densities of the
initial state and of the inlet are scaled down where AO exceeds ``ao_limit`` AO_max (as
the SUMO bridge does at a twin start); if the twin still leaves the physical domain, the
run stops there and the later periods are NaN (the fit turns them into a penalty).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from arzsumo.errors import ArzsumoError
from arzsumo.identify.data import IdentifyError, ReplayData
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import area_occupancy
from arzsumo.model.params import ModelParameters
from arzsumo.pde.boundary import Inlet
from arzsumo.pde.solver import SolverOptions, TwinStepper, TwinStoppedError
from arzsumo.pde.state import cell_centres
from arzsumo.pde.supply import ReceivingCapacity

#: an inlet rule of :func:`run_replay`: (held state, first cell's state) -> boundary state
InletRule = Callable[[np.ndarray, np.ndarray], np.ndarray]
#: the inlet fluxes of :class:`ReplayOptions`
INLETS = ("ctm", "supply", "ghost")


@dataclass(frozen=True)
class ReplayOptions:
    """Numerics of the replay twin (``scheme``, ``flux``, ``limiter``, ``cfl`` and
    ``max_steps``, the safety limit on the time steps of one replay, as
    :class:`arzsumo.pde.SolverOptions`)."""

    #: finite volumes on [0, L] (50 cells of 20 m by default: see
    #: ``benchmarks/bench_identify.py`` for cost and accuracy against finer grids)
    cells: int = 50
    scheme: str = "first"
    flux: str = "hll"
    limiter: str = "vanleer"
    cfl: float = 0.9
    #: densities of the initial and inlet states are scaled down to AO <= ao_limit AO_max
    #: of the parameters being tried, in (0, 1)
    ao_limit: float = 0.98
    max_steps: int = 1_000_000
    #: the inlet flux: min(demand of the held state, supply of the first cell) (``ctm``),
    #: the held state's physical flux limited to the supply (``supply``), or that flux as
    #: it is (``ghost``, as the bridge's replay twin)
    inlet: str = "ctm"

    def __post_init__(self) -> None:
        self.solver()                                   # validates the numerics
        if not 0.0 < self.ao_limit < 1.0:
            raise IdentifyError(f"ao_limit = {self.ao_limit!r} is not allowed: a fraction "
                                "of AO_max in (0, 1)")
        if self.inlet not in INLETS:
            raise IdentifyError(f"inlet = {self.inlet!r} is not allowed: one of "
                                f"{', '.join(INLETS)}")

    def solver(self) -> SolverOptions:
        """The twin's :class:`SolverOptions` for these numerics."""
        return SolverOptions(cells=self.cells, scheme=self.scheme, flux=self.flux,
                             limiter=self.limiter, cfl=self.cfl, max_steps=self.max_steps)


@dataclass(frozen=True)
class HeldInlet(Inlet):
    """A ghost-cell inlet: the boundary state at x = 0 is ``state``, set per period.

    The fields of :class:`Inlet` (densities, flow, l4) are not used; ``state`` holds
    (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) and is overwritten in place by :meth:`hold`.
    With ``supply`` the flux of the boundary state is limited to the first cell's
    receiving capacity, with ``sending`` too a congested boundary state demands the
    capacity; ``theta`` holds the factor of the last flux (1.0: the state's own flux).
    """

    state: np.ndarray = field(default_factory=lambda: np.ones(4))
    #: a boundary rule instead of the ghost cell (:data:`InletRule`)
    rule: InletRule | None = None
    supply: ReceivingCapacity | None = None
    sending: bool = False
    theta: np.ndarray = field(default_factory=lambda: np.ones(1))

    def hold(self, z: np.ndarray) -> None:
        """Hold the boundary state ``z`` (4,) from now on."""
        self.state[:] = z

    def boundary_primitive(self, t: float, z0: np.ndarray) -> np.ndarray:
        return self.state if self.rule is None else self.rule(self.state, z0)

    def boundary_flux(self, p: ModelParameters, t: float,
                      z0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The boundary state's flux (4,), supply-limited with ``supply``, and the state."""
        flux, qb = super().boundary_flux(p, t, z0)
        if self.supply is not None:
            sender = (float(qb[0]), float(qb[2])) if self.sending else None
            flux, self.theta[0] = self.supply.limit(flux, float(z0[0]), float(z0[2]), sender)
        return flux, qb


@dataclass(frozen=True)
class ReplayRun:
    """Fields of one replay and how it ended (vehicle counts until the stop, if any)."""

    #: predicted (rho_h, v_h, rho_a, v_a) at (data.t, data.x), (T, 4, N); NaN from the
    #: period in which the twin stopped
    fields: np.ndarray
    #: time (s) at which the twin left the physical domain (None if it completed), and
    #: the twin's stop message ("" if it completed)
    stopped: float | None
    reason: str
    steps: int
    #: vehicles that left at x = L
    vehicles_out: float = 0.0
    #: seconds during which the arriving flow, not ``data.outflow``, set the outflow (the
    #: last cell was in free flow and could not deliver it)
    outlet_limited: float = 0.0
    #: vehicles that entered at x = 0
    vehicles_in: float = 0.0
    #: seconds during which the first cell's supply or the held state's demand, not the
    #: held state's own flux, set the inflow (inlets ``ctm`` and ``supply``)
    inlet_limited: float = 0.0


def _not_regime(record: logging.LogRecord) -> bool:
    """Drop the twin's free-flow warning: it is about the l4 inlet, which is not used here."""
    return not str(record.msg).startswith("the equilibrium is in free flow")


@contextmanager
def _quiet_regime() -> Iterator[None]:
    logger = logging.getLogger("arzsumo.pde.solver")
    logger.addFilter(_not_regime)
    try:
        yield
    finally:
        logger.removeFilter(_not_regime)


def replay_grid(params: ModelParameters, options: ReplayOptions) -> np.ndarray:
    """Cell centres (m) of the replay twin."""
    return cell_centres(params.length, options.cells)


def admissible(params: ModelParameters, z: np.ndarray, ao_limit: float) -> np.ndarray:
    """Primitive states ``z`` (4, n) with densities scaled to AO <= ao_limit AO_max."""
    ao = area_occupancy(params, z[0], z[2])
    scale = np.minimum(1.0, ao_limit * params.ao_max / ao)
    if np.all(scale == 1.0):
        return z
    out = np.array(z, float)
    out[[0, 2]] *= scale
    return out


def on_grid(values: np.ndarray, x_from: np.ndarray, x_to: np.ndarray) -> np.ndarray:
    """Rows of ``values`` (4, len(x_from)) linearly interpolated to ``x_to`` (held at ends)."""
    if x_from.shape == x_to.shape and np.array_equal(x_from, x_to):
        return values
    return np.vstack([np.interp(x_to, x_from, row) for row in values])


def _stepper(params: ModelParameters, data: ReplayData, options: ReplayOptions,
             x_twin: np.ndarray, rule: InletRule | None = None
             ) -> tuple[TwinStepper, HeldInlet]:
    init = admissible(params, on_grid(data.initial, data.x, x_twin), options.ao_limit)
    eq = Equilibrium(params, float(init[0].mean()), float(init[2].mean()))
    supply = ReceivingCapacity(params) if options.inlet != "ghost" else None
    inlet = HeldInlet(eq.rho_h, eq.rho_a, eq.q, np.zeros(4), rule=rule, supply=supply,
                      sending=options.inlet == "ctm")
    with _quiet_regime():
        return TwinStepper(eq, init, options.solver(), inlet), inlet


def run_replay(params: ModelParameters, data: ReplayData,
               options: ReplayOptions | None = None, *,
               inlet_rule: InletRule | None = None) -> ReplayRun:
    """Replay ``data`` with the twin under ``params``; see the module docstring.

    Parameters
    ----------
    data : ReplayData
        ``data.x`` must lie in [0, params.length].
    inlet_rule : callable, optional
        The boundary state at x = 0 from the held (measured) state and the first cell's
        state, instead of the ghost cell holding the measured state (an alternative inlet
        condition; ``arzsumo study inlet``).

    Returns
    -------
    ReplayRun
        Never raises for a parameter set under which the twin leaves the physical domain:
        ``stopped`` and ``reason`` say when and why, and the fields are NaN from there.
    """
    opts = options if options is not None else ReplayOptions()
    if data.x[-1] > params.length:
        raise IdentifyError(f"{data.name}: x reaches {data.x[-1]} m, beyond the road length "
                            f"L = {params.length} m; allowed: positions in [0, L]")
    x_twin = replay_grid(params, opts)
    out = np.full((data.periods, 4, data.x.size), np.nan)
    inlet_states = admissible(params, data.inlet.T, opts.ao_limit).T
    try:
        stepper, inlet = _stepper(params, data, opts, x_twin, inlet_rule)
    except ArzsumoError as exc:                        # start state not representable
        return ReplayRun(out, 0.0, str(exc), 0)
    clock = _LimitClock(inlet, stepper.t)
    for k in range(data.periods):
        inlet.hold(inlet_states[k])
        try:
            stepper.advance(float(data.t[k]), float(data.outflow[k]) - stepper.q_star,
                            clock if inlet.supply is not None else None)
        except TwinStoppedError as exc:
            return ReplayRun(out, exc.t, str(exc), stepper.steps, stepper.outflow,
                             stepper.outlet_limited_time, stepper.inflow, clock.limited)
        out[k] = on_grid(stepper.primitive(), x_twin, data.x)
    return ReplayRun(out, None, "", stepper.steps, stepper.outflow, stepper.outlet_limited_time,
                     stepper.inflow, clock.limited)


class _LimitClock:
    """Step callback: the seconds in which the inlet's last flux was not the held state's."""

    def __init__(self, inlet: HeldInlet, t0: float) -> None:
        self.inlet, self.t, self.limited = inlet, t0, 0.0

    def __call__(self, t: float, q: np.ndarray, vehicles_in: float,
                 vehicles_out: float) -> None:
        if self.inlet.theta[0] != 1.0:
            self.limited += t - self.t
        self.t = t


def replay(params: ModelParameters, data: ReplayData,
           options: ReplayOptions | None = None) -> np.ndarray:
    """Predicted fields (T, 4, N) of ``data`` under ``params``; NaN after a twin stop."""
    return run_replay(params, data, options).fields
