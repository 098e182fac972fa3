"""The two PDE twins that run beside SUMO: *replay* and *reference*.

Both start from the aggregated microscopic state at the start of control and take the
measured state of SUMO's first cell, smoothed exponentially, as their boundary state at
x = 0 (a ghost cell), so their inflow follows SUMO's.

* *replay* is given the outflow SUMO produced at x = L (smoothed with the same time
  constant, which keeps the vehicle count): how well the model explains SUMO.
* *reference* runs its own closed loop with a copy of the controller: what the design
  promised.

When a step would leave the model's physical domain (SUMO can hold area occupancies the
calibrated fundamental diagram cannot), a twin is re-synchronised to the aggregated micro
state of that period and goes on; every re-synchronisation is counted, and the period it
happens in is excluded from the fidelity measures (NaN fields).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arzsumo.bridge.estimator import fill_speeds
from arzsumo.control.base import Controller
from arzsumo.model.characteristic import Linearization
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import area_occupancy
from arzsumo.model.params import ModelParameters
from arzsumo.sumo.measure import CellData
from arzsumo.twin.boundary import Inlet
from arzsumo.twin.solver import SolverOptions, TwinStepper, TwinStoppedError

log = logging.getLogger(__name__)


def to_twin_grid(params: ModelParameters, data: CellData, x_twin: np.ndarray,
                 ao_limit: float = 0.9) -> tuple[np.ndarray, float]:
    """Micro cell data interpolated to the twin's cells, made admissible for the model.

    Densities are scaled down where the calibrated model could not hold them (AO above
    ``ao_limit`` of its maximum); returns the fields (4, n) and the vehicles removed (veh).
    """
    v_h, v_a = fill_speeds(params, data.rho_h, data.v_h, data.rho_a, data.v_a)
    rho_h = np.maximum(np.interp(x_twin, data.x, data.rho_h), 1e-4)
    rho_a = np.maximum(np.interp(x_twin, data.x, data.rho_a), 1e-4)
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

    holder: _InletState = field(default_factory=lambda: _InletState(np.zeros(4)))

    def boundary_primitive(self, t: float, z0: np.ndarray) -> np.ndarray:
        return self.holder.values


class MeasuredInlet:
    """Exponentially smoothed inlet state measured in SUMO's first cell, for the twins.

    The densities and speeds of the first micro cell (and, where a class is absent, its
    equilibrium speed) are smoothed with time constant ``tau`` (s).
    """

    def __init__(self, eq: Equilibrium, lin: Linearization, tau: float) -> None:
        self.params, self.tau = eq.params, tau
        self.state = _InletState(np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a]))
        self.inlet = _GhostInlet(eq.rho_h, eq.rho_a, eq.q, lin.T[3], self.state)

    def update(self, data: CellData, dt: float) -> None:
        """Smooth in the first cell of ``data`` over ``dt`` seconds."""
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
    """One twin run alongside SUMO, re-synchronised when it would leave the domain."""

    mode: str
    stepper: TwinStepper
    resyncs: list[float] = field(default_factory=list)
    reasons: list[str] = field(default_factory=list)
    _fresh: bool = False

    def advance(self, t: float, u: float, resync: Callable[[], np.ndarray]) -> None:
        """Advance to ``t`` (s) under U = ``u`` (veh/s); re-sync from ``resync()`` on failure."""
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

    def status(self) -> dict[str, Any]:
        """Re-synchronisations: count, first time (s) and its reason."""
        return {"resyncs": len(self.resyncs),
                "first_resync_s": self.resyncs[0] if self.resyncs else None,
                "first_reason": self.reasons[0] if self.reasons else ""}


class TwinPair:
    """The replay and reference twins, started from the measured state at control start.

    Parameters
    ----------
    eq, lin : Equilibrium, Linearization
        The design's operating point.
    start : CellData
        Micro state at the start of control (t = 0 of both twins).
    opts : SolverOptions
        Twin grid, scheme, horizon and control period.
    smoothing : float
        Time constant of the measured boundary data, s.
    reference_controller : Controller
        The reference twin's own controller (already reset).
    q_nominal : float
        Outflow of the nominal meter plan, veh/s: the replayed outflow's start value.
    """

    def __init__(self, eq: Equilibrium, lin: Linearization, start: CellData,
                 opts: SolverOptions, smoothing: float, reference_controller: Controller,
                 q_nominal: float) -> None:
        self.eq, self.params, self.smoothing = eq, eq.params, smoothing
        self.controller = reference_controller
        self.inlet = MeasuredInlet(eq, lin, smoothing)
        self.inlet.start(start)
        self.q_out = q_nominal
        self.x = (np.arange(opts.cells) + 0.5) * self.params.length / opts.cells
        fields, removed = to_twin_grid(self.params, start, self.x)
        if removed > 0.5:
            log.info("twin start: %.1f vehicles removed where the model cannot hold them",
                     removed)
        self.replay, self.reference = (
            Twin(mode, TwinStepper(eq, fields, opts, self.inlet.inlet, t0=0.0))
            for mode in ("replay", "reference"))

    def check_reference(self) -> float:
        """The reference controller's U (veh/s) on the reference twin's state."""
        return self.controller.check(self.reference.stepper.macro_state())

    def advance(self, data: CellData, t: float, period: float, u_reference: float) -> None:
        """Advance both twins to ``t`` (s) after a period of ``period`` s that SUMO
        measured as ``data``; the reference twin under ``u_reference`` (veh/s)."""
        self.inlet.update(data, period)
        self.q_out += (1.0 - math.exp(-period / self.smoothing)) * (
            data.outflow_h + data.outflow_a - self.q_out)

        def resync() -> np.ndarray:
            return to_twin_grid(self.params, data, self.x)[0]

        self.replay.advance(t, self.q_out - self.eq.q, resync)
        self.reference.advance(t, u_reference, resync)

    def status(self) -> dict[str, dict[str, Any]]:
        return {"replay": self.replay.status(), "reference": self.reference.status()}
