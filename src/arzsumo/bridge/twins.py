"""The two PDE twins that run beside SUMO: *replay* and *reference*.

Both start from SUMO's state at the start of control and hold its first cell, smoothed,
in a ghost cell at x = 0. *replay* is given SUMO's outflow at x = L, smoothed alike: how
well the model explains SUMO. *reference* runs its own closed loop with a copy of the
controller: what the design promised. A twin whose step would leave the model's domain is
re-synchronised to SUMO's state, counted, and the period left out (NaN fields).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

import numpy as np

from arzsumo.bridge.boundary_data import measured_state, smooth_step
from arzsumo.control.base import Controller
from arzsumo.identify.replay import admissible, on_grid
from arzsumo.model.characteristic import Linearization
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import ModelParameters
from arzsumo.pde.boundary import Inlet
from arzsumo.pde.solver import SolverOptions, TwinStepper, TwinStoppedError
from arzsumo.pde.state import cell_centres
from arzsumo.sumo.measure import CellData

log = logging.getLogger(__name__)


#: the twins' densities are scaled down to AO <= TWIN_AO_LIMIT AO_max where SUMO holds more
#: than the model can (the start state, a re-synchronisation and the inlet state)
TWIN_AO_LIMIT = 0.9


def to_twin_grid(params: ModelParameters, data: CellData, x_twin: np.ndarray,
                 ao_limit: float = TWIN_AO_LIMIT) -> tuple[np.ndarray, float]:
    """Micro cell data interpolated to the twin's cells ``x_twin``, densities scaled down
    where the model could not hold them (AO above ``ao_limit`` AO_max), as the
    identification's replay twin starts; returns the fields (4, n) and the vehicles
    removed (veh).
    """
    measured = on_grid(measured_state(params, data.rho_h, data.v_h, data.rho_a, data.v_a),
                       data.x, x_twin)
    fields = admissible(params, measured, ao_limit)
    dx = x_twin[1] - x_twin[0]
    removed = float(np.sum(measured[[0, 2]] - fields[[0, 2]]) * dx)
    return fields, removed


@dataclass(frozen=True)
class _GhostInlet(Inlet):
    """An inlet whose boundary state is the measured one (a ghost cell), not the l4 solve.

    SUMO's first cell is far from the model's equilibrium at times (AVs crawl while HVs
    pass); the paper's inlet condition, linear in the outgoing Riemann variable, can then
    give negative boundary speeds. The measured state, smoothed, is always admissible.
    """

    #: ``values``: the inlet state (rho_h, v_h, rho_a, v_a) the ghost cell holds, SI
    holder: SimpleNamespace = field(default_factory=lambda: SimpleNamespace(values=np.zeros(4)))

    def boundary_primitive(self, t: float, z0: np.ndarray) -> np.ndarray:
        return self.holder.values


class MeasuredInlet:
    """SUMO's first cell, measured and smoothed with time constant ``tau`` (s) as
    :func:`~arzsumo.bridge.boundary_data.inlet_series` does for a whole run; the ghost cell
    holds it with densities scaled to AO <= ``ao_limit`` AO_max."""

    def __init__(self, eq: Equilibrium, lin: Linearization, tau: float,
                 ao_limit: float = TWIN_AO_LIMIT) -> None:
        self.params, self.tau, self.ao_limit = eq.params, tau, ao_limit
        self.smoothed = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])
        self.state = SimpleNamespace(values=np.array(self.smoothed, float))
        self.inlet = _GhostInlet(eq.rho_h, eq.rho_a, eq.q, lin.T[3], self.state)

    def _first(self, data: CellData) -> np.ndarray:
        return measured_state(self.params, data.rho_h[:1], data.v_h[:1], data.rho_a[:1],
                              data.v_a[:1])[:, 0]

    def _hold(self) -> None:
        self.state.values = admissible(self.params, self.smoothed[:, None], self.ao_limit)[:, 0]

    def update(self, data: CellData, dt: float) -> None:
        """Smooth in the first cell of ``data`` over ``dt`` seconds."""
        self.smoothed = smooth_step(self.smoothed, self._first(data), dt, self.tau)
        self._hold()

    def start(self, data: CellData) -> None:
        """Start from the measured first cell (no smoothing history)."""
        self.smoothed = self._first(data)
        self._hold()


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
        return np.vstack([np.interp(x, self.stepper.x, row) for row in self.stepper.primitive()])

    def status(self) -> dict[str, Any]:
        """Re-synchronisations: count, first time (s) and its reason."""
        return {"resyncs": len(self.resyncs),
                "first_resync_s": self.resyncs[0] if self.resyncs else None,
                "first_reason": self.reasons[0] if self.reasons else ""}


class TwinPair:
    """The replay and reference twins, started from the measured state at control start.

    ``eq``, ``lin``: the design's operating point; ``start``: the micro state at t = 0;
    ``opts``: twin grid, scheme, horizon and control period; ``smoothing``: time constant
    of the measured boundary data, s; ``reference_controller``: the reference twin's own
    (reset); ``q_nominal``: outflow of the nominal plan, veh/s, the replayed outflow's start.
    """

    def __init__(self, eq: Equilibrium, lin: Linearization, start: CellData,
                 opts: SolverOptions, smoothing: float, reference_controller: Controller,
                 q_nominal: float) -> None:
        self.eq, self.params, self.smoothing = eq, eq.params, smoothing
        self.controller = reference_controller
        self.inlet = MeasuredInlet(eq, lin, smoothing)
        self.inlet.start(start)
        self.q_out = q_nominal
        self.x = cell_centres(self.params.length, opts.cells)
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
        self.q_out = smooth_step(self.q_out, data.outflow_h + data.outflow_a, period,
                                 self.smoothing)

        def resync() -> np.ndarray:
            return to_twin_grid(self.params, data, self.x)[0]

        self.replay.advance(t, self.q_out - self.eq.q, resync)
        self.reference.advance(t, u_reference, resync)

    def status(self) -> dict[str, dict[str, Any]]:
        return {"replay": self.replay.status(), "reference": self.reference.status()}
