"""Micro to macro: Edie's space-time density, flow and speed per class on a cell grid,
from the vehicles on ``main`` read every SUMO step (formulas: docs/sumo.md, "Micro to
macro"). Class flows count the vehicles that appeared on ``main`` (x = 0; initial
vehicles, ids with ``_init``, excepted) and that left it (x = L).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from arzsumo.errors import require
from arzsumo.sumo.layout import RoadLayout, VehicleClasses
from arzsumo.sumo.network import MAIN


@dataclass(frozen=True)
class CellData:
    """Edie aggregates over one window ending at ``t`` (SI).

    ``rho_*`` veh/m, ``q_*`` veh/s, ``v_*`` m/s (NaN in cells no vehicle of the class
    visited), ``samples_*`` vehicle-steps per cell, ``inflow_*``/``outflow_*`` class
    flows at x = 0 and x = L over the window, veh/s.
    """

    t: float
    window: float
    x: np.ndarray
    rho_h: np.ndarray
    rho_a: np.ndarray
    q_h: np.ndarray
    q_a: np.ndarray
    samples_h: np.ndarray
    samples_a: np.ndarray
    inflow_h: float
    inflow_a: float
    outflow_h: float
    outflow_a: float

    @property
    def v_h(self) -> np.ndarray:
        """HV space-mean speed per cell, m/s (NaN where empty)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.samples_h > 0, self.q_h / self.rho_h, np.nan)

    @property
    def v_a(self) -> np.ndarray:
        """AV space-mean speed per cell, m/s (NaN where empty)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.samples_a > 0, self.q_a / self.rho_a, np.nan)


class EdieGrid:
    """Accumulates per-step vehicle samples on a uniform grid over [0, ``length``] (m):
    cells of ``cell_length`` dx (m, dividing L), samples every ``dt`` s."""

    def __init__(self, length: float, cell_length: float, dt: float) -> None:
        n = length / cell_length
        require(abs(n - round(n)) < 1e-9 and n >= 1, "cell_length", cell_length,
                f"a length dividing the road length {length} m")
        self.length, self.dx, self.dt, self.n = length, cell_length, dt, round(n)
        self.x = (np.arange(self.n) + 0.5) * cell_length
        self.reset()

    def reset(self) -> None:
        """Start a new window."""
        self._cnt = np.zeros((2, self.n))
        self._dist = np.zeros((2, self.n))
        self.steps = 0
        self.flows = np.zeros(4)          # in_h, in_a, out_h, out_a (vehicles)

    def add(self, pos: np.ndarray, speed: np.ndarray, av: np.ndarray) -> None:
        """Add one step's samples: positions (m), speeds (m/s), AV mask."""
        idx = np.minimum((pos / self.dx).astype(np.intp), self.n - 1) + self.n * av
        self._cnt += np.bincount(idx, minlength=2 * self.n).reshape(2, self.n)
        self._dist += np.bincount(idx, weights=speed, minlength=2 * self.n).reshape(2, self.n)
        self.steps += 1

    def flush(self, t: float) -> CellData:
        """Aggregates of the window ending at ``t`` (s); starts a new window."""
        require(self.steps > 0, "window", 0, "at least one step before flush")
        span = self.steps * self.dt
        rho = self._cnt * self.dt / (self.dx * span)
        q = self._dist * self.dt / (self.dx * span)
        data = CellData(float(t), span, self.x.copy(), rho[0], rho[1], q[0], q[1],
                        self._cnt[0].copy(), self._cnt[1].copy(), *map(float, self.flows / span))
        self.reset()
        return data


@dataclass
class MeasurementLog:
    """Stacked :class:`CellData` of a run (arrays of shape (windows, cells))."""

    records: list[CellData] = field(default_factory=list)

    def append(self, data: CellData) -> None:
        self.records.append(data)

    def array(self, name: str) -> np.ndarray:
        """One field over all windows, e.g. ``log.array("rho_h")``."""
        return np.array([getattr(r, name) for r in self.records])


class MainlineSensor:
    """Collects ``main`` every step from an open libsumo run and yields windows.

    Call :meth:`collect` after every SUMO step; when :attr:`steps_per_window` steps have
    been collected it returns the window's :class:`CellData` (otherwise None). With a
    ``layout`` (a user's network) the section is its edges from x = 0 to x = L, every
    lane: Edie's sums run over all of them, so the densities are per road.
    """

    def __init__(self, lib: ModuleType, length: float, cell_length: float, dt: float,
                 steps_per_window: int, layout: RoadLayout | None = None,
                 classes: VehicleClasses | None = None) -> None:
        require(steps_per_window >= 1, "steps_per_window", steps_per_window, "at least 1")
        self.lib, self.grid = lib, EdieGrid(length, cell_length, dt)
        self.steps_per_window = steps_per_window
        self.layout = layout
        self.classes = classes or VehicleClasses(lib, layout)
        self._prev: set[str] = set()

    def sample(self) -> tuple[tuple[str, ...], np.ndarray, np.ndarray, np.ndarray]:
        """(ids, positions m, speeds m/s, AV mask) of the vehicles on ``main`` now."""
        if self.layout is not None:
            return self._sample_section(self.layout)
        v = self.lib.vehicle
        ids = self.lib.edge.getLastStepVehicleIDs(MAIN)
        n = len(ids)
        pos = np.fromiter(map(v.getLanePosition, ids), float, n)
        speed = np.fromiter(map(v.getSpeed, ids), float, n)
        return ids, pos, speed, self.classes.av_mask(ids)

    def _sample_section(self, layout: RoadLayout
                        ) -> tuple[tuple[str, ...], np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`sample` on a user's section: x = the edge's start + the lane position,
        vehicles in [0, L) only (internal edges between section edges count at the next
        edge's start)."""
        v, edge = self.lib.vehicle, self.lib.edge
        ids: list[str] = []
        xs: list[float] = []
        for e, x0 in layout.section_places():
            on = edge.getLastStepVehicleIDs(e)
            if not on:
                continue
            internal = e.startswith(":")
            ids += on
            xs += [x0] * len(on) if internal else [x0 + v.getLanePosition(i) for i in on]
        pos = np.asarray(xs, float)
        keep = (pos >= 0.0) & (pos < layout.length)
        ids_in = tuple(i for i, k in zip(ids, keep, strict=True) if k)
        speed = np.fromiter(map(v.getSpeed, ids_in), float, len(ids_in))
        return ids_in, pos[keep], speed, self.classes.av_mask(ids_in)

    def collect(self, t: float) -> CellData | None:
        """Sample the current step (time ``t``, s); return a finished window or None."""
        ids, pos, speed, av = self.sample()
        # for the sensor's speed moments and AV probes
        self.last_ids, self.last_pos, self.last_speed, self.last_av = ids, pos, speed, av
        self.grid.add(pos, speed, av)
        cur = set(ids)
        entered = {i for i in cur - self._prev if "_init" not in i}   # placed at t = 0: not inflow
        is_av_id = self.classes.av
        for k, moved in ((0, entered), (2, self._prev - cur)):       # in (0, 1), out (2, 3)
            if moved:
                na = sum(1 for i in moved if is_av_id(i))
                self.grid.flows[k] += len(moved) - na
                self.grid.flows[k + 1] += na
        self._prev = cur
        return self.grid.flush(t) if self.grid.steps >= self.steps_per_window else None
