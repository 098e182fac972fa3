"""Induction loops (E1) on ``main``: per-class counts, mean spot speeds and occupancy.

A loop station is one E1 across the lane (one per lane on a user's section), read every
step with ``inductionloop.getVehicleData``; once per control period :class:`LoopSensor`
returns a :class:`~arzsumo.estimate.observations.LoopObservation` per class: flow (veh/s),
speed (m/s, time-mean or harmonic, ``[sensing] loop_speed``) and density (veh/m). Their
definitions, where the boundary stations sit and why SUMO's interval getters are not used:
docs/sumo.md, "Sensing layouts".
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from types import ModuleType
from xml.sax.saxutils import quoteattr

import numpy as np

from arzsumo.errors import ScenarioError, require
from arzsumo.estimate.observations import LoopNoise, LoopObservation
from arzsumo.io import atomic_file
from arzsumo.sumo.layout import RoadLayout
from arzsumo.sumo.network import DOWN, MAIN
from arzsumo.sumo.vtypes import AV_TYPE

#: Distance of the downstream boundary station before x = L, m (a loop must lie on the lane).
BOUNDARY_GAP = 0.1
#: Position of the upstream boundary station, m: beyond the front of any vehicle inserted
#: at x = 0 (vtypes.MAX_LENGTH + 0.1 m; a test checks it).
INLET_GAP = 6.0
#: Floor of the spot speeds in the harmonic mean, m/s: a vehicle can reach the loop and
#: stop within the step (its reading 0, 1/v infinite, the period's mean 0). 5x SUMO's
#: halting threshold and far below the class means (14-40 km/h on the default), it only
#: caps the weight of a vehicle crawling over the loop; the time-mean is not floored.
V_MIN = 0.5
#: what a loop reports as a class's speed: the arithmetic (time-mean) or the harmonic
#: mean of the spot speeds of the vehicles that crossed it in the period
LOOP_SPEEDS = ("time_mean", "harmonic")


def loop_ids(n: int) -> list[str]:
    """Ids of the stations, upstream first."""
    return [f"e1_{j:03d}" for j in range(n)]


def placed_positions(x: Sequence[float], length: float) -> np.ndarray:
    """Where SUMO puts stations asked for at ``x`` (m) on a section of ``length`` L (m).

    Positions must lie in [0, L] and be distinct; they are sorted, and those before
    :data:`INLET_GAP` (6 m) or after L - :data:`BOUNDARY_GAP` are moved there.
    """
    arr = np.sort(np.asarray(x, dtype=float))
    require(arr.ndim == 1 and arr.size >= 1, "loop_positions", list(arr),
            "at least one position in m", ScenarioError)
    require(bool(np.all(np.isfinite(arr))) and arr[0] >= 0 and arr[-1] <= length,
            "loop_positions", [float(v) for v in arr], f"positions in [0, {length:g}] m",
            ScenarioError)
    placed = np.clip(arr, INLET_GAP, length - BOUNDARY_GAP)
    require(bool(np.all(np.diff(placed) > 0)), "loop_positions", [float(v) for v in arr],
            f"distinct positions, at most one below {INLET_GAP:g} m and one above "
            f"{length - BOUNDARY_GAP:g} m", ScenarioError)
    return placed


def lane_loop_ids(station: str, lanes: int) -> list[str]:
    """Ids of a station's E1 loops on a user's section, one per lane (lane 0 first)."""
    return [f"{station}_{k}" for k in range(lanes)]


def _e1(det: str, lane: str, pos: float) -> dict[str, str]:
    """An E1 element of an additional file (its file output off: libsumo reads it)."""
    return {"id": det, "lane": lane, "pos": f"{pos:.3f}", "period": "3600", "file": "NUL"}


def _write_e1s(path: Path, elements: list[dict[str, str]]) -> Path:
    """Write a SUMO additional file of the E1 ``elements`` atomically; return its path."""
    lines = ["    <inductionLoop " + " ".join(f"{a}={quoteattr(v)}" for a, v in e.items()) + "/>"
             for e in elements]
    with atomic_file(path) as tmp:
        tmp.write_text("<additional>\n" + "\n".join(lines) + "\n</additional>\n",
                       encoding="utf-8")
    return path


def _vehicle_data(lib: ModuleType, ids: Sequence[str]) -> Sequence[tuple]:
    """The vehicles on the E1 loops ``ids`` in the step (every lane's)."""
    data = lib.inductionloop.getVehicleData
    return data(ids[0]) if len(ids) == 1 else [row for i in ids for row in data(i)]


def write_loops(path: Path, x: Sequence[float], length: float,
                layout: RoadLayout | None = None) -> Path:
    """Write an additional file with one E1 station per position of ``main_0``; on a
    user's section (``layout``) a station is one E1 per lane of the edge at x."""
    placed = placed_positions(x, length)
    ids = loop_ids(placed.size)
    if layout is None:
        elements = [_e1(det, f"{MAIN}_0", pos) for det, pos in zip(ids, placed, strict=True)]
    else:
        elements = []
        for station, xj in zip(ids, placed, strict=True):
            edge, pos = layout.locate(float(xj))
            elements += [_e1(det, f"{edge}_{k}", pos)
                         for k, det in enumerate(lane_loop_ids(station, layout.lanes))]
    return _write_e1s(path, elements)


def speed_means(entered: np.ndarray, speed_sum: np.ndarray, inverse_sum: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """Time-mean and harmonic speeds, m/s, from per-loop sums of N spot speeds.

    ``entered``: N; ``speed_sum``: sum of the spot speeds v_k, m/s; ``inverse_sum``: sum of
    1 / max(v_k, :data:`V_MIN`), s/m. NaN where N = 0; by the AM-HM inequality harmonic <=
    time-mean wherever no v_k < V_MIN (equal for N = 1).
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        time_mean = np.where(entered > 0, speed_sum / entered, np.nan)
        harmonic = np.where(entered > 0, entered / inverse_sum, np.nan)
    return time_mean, harmonic


class LoopSensor:
    """Reads the stations of :func:`write_loops` every step; one record per period.

    ``x``: station positions asked for, m (as given to :func:`write_loops`) on a section of
    ``length`` L, m; ``dt``: SUMO step, s; ``noise``: attached to the records (for the
    estimators); ``speed``: which mean of the spot speeds the records' ``speed`` is
    (:data:`LOOP_SPEEDS`; both are kept on them).
    """

    def __init__(self, lib: ModuleType, x: Sequence[float], length: float, dt: float,
                 steps_per_period: int, noise: LoopNoise | None = None,
                 speed: str = "time_mean", layout: RoadLayout | None = None) -> None:
        require(steps_per_period >= 1, "steps_per_period", steps_per_period, "at least 1")
        require(speed in LOOP_SPEEDS, "loop_speed", speed, f"one of {', '.join(LOOP_SPEEDS)}")
        self.lib, self.dt, self.steps_per_period, self.speed = lib, dt, steps_per_period, speed
        self.x = placed_positions(x, length)
        self.ids = loop_ids(self.x.size)
        #: the E1 loops of each station (one; one per lane on a user's section), and the
        #: vTypes counted as AVs
        self.lanes = [[i] for i in self.ids] if layout is None else \
            [lane_loop_ids(i, layout.lanes) for i in self.ids]
        self.av_types = frozenset({AV_TYPE}) if layout is None else layout.av_types
        self.noise = noise or LoopNoise()
        self._on: list[set[str]] = [set() for _ in self.ids]
        self._reset()

    def _reset(self) -> None:
        n = self.x.size
        self.entered = np.zeros((2, n))      # vehicles whose front reached the loop
        self.speed_sum = np.zeros((2, n))    # their speeds then, m/s
        self.inverse_sum = np.zeros((2, n))  # 1 / max(speed, V_MIN), s/m
        self.dwell = np.zeros((2, n))        # sum of time on loop / length, s/m
        self.steps = 0

    def _read(self, j: int, t: float) -> None:
        """Add station ``j``'s vehicles of the step ending at ``t`` (s)."""
        on, t0 = set(), t - self.dt
        for vid, length, t_in, t_out, vtype in _vehicle_data(self.lib, self.lanes[j]):
            c = 1 if vtype in self.av_types else 0
            on.add(vid)
            if vid not in self._on[j]:
                v = self.lib.vehicle.getSpeed(vid)
                self.entered[c, j] += 1
                self.speed_sum[c, j] += v
                self.inverse_sum[c, j] += 1.0 / max(v, V_MIN)
            end = t if t_out < 0 else min(t_out, t)
            self.dwell[c, j] += max(end - max(t_in, t0), 0.0) / length
        self._on[j] = on

    def observe(self, t: float) -> LoopObservation | None:
        """Read the step that ended at ``t`` (s); the period's record when it is complete."""
        for j in range(self.x.size):
            self._read(j, t)
        self.steps += 1
        if self.steps < self.steps_per_period:
            return None
        span = self.steps * self.dt
        time_mean, harmonic = speed_means(self.entered, self.speed_sum, self.inverse_sum)
        speed = harmonic if self.speed == "harmonic" else time_mean
        obs = LoopObservation(float(t), span, self.x, self.entered / span, speed,
                              self.dwell / span, self.noise, time_mean, harmonic)
        self._reset()
        return obs


#: id of the E1 loop downstream of the merge (ALINEA's measurement)
DOWNSTREAM_LOOP = "e1_down"
#: its default distance past the merge nose (the start of ``down``), m
DOWNSTREAM_DISTANCE = 100.0


def downstream_ids(layout: RoadLayout | None) -> list[str]:
    """Ids of the downstream loop: one on ``down``, one per lane on a user's network."""
    return [DOWNSTREAM_LOOP] if layout is None else \
        lane_loop_ids(DOWNSTREAM_LOOP, layout.outlet_lanes)


def write_downstream_loop(path: Path, distance: float = DOWNSTREAM_DISTANCE,
                          layout: RoadLayout | None = None) -> Path:
    """Write an additional file with one E1 loop on ``down_0`` at ``distance`` m past the
    merge nose (the end of ``merge`` is the start of ``down``). On a user's network
    (``layout``): one E1 per lane on the first mainline edge past the ramp's junction,
    ``distance`` m along it (at most its length less 0.1 m)."""
    require(0 < distance < 500, "loop_distance", distance,
            "a distance in (0, 500) m on the 500 m `down` edge", ScenarioError)
    if layout is None:
        return _write_e1s(path, [_e1(DOWNSTREAM_LOOP, f"{DOWN}_0", distance)])
    pos = min(distance, layout.outlet_length - BOUNDARY_GAP)
    return _write_e1s(path, [_e1(det, f"{layout.outlet_edge}_{k}", pos)
                             for k, det in enumerate(downstream_ids(layout))])


class DownstreamLoop:
    """Reads the loop of :func:`write_downstream_loop` every step; occupancy and flow per
    control period.

    Per period of T = ``steps_per_period`` steps of ``dt`` s: the occupancy o = (1/T) sum
    tau_k (a fraction, the mean over the lanes' E1s; side-by-side vehicles each count, so
    o may exceed 1, as SUMO's own E1 occupancy does) and the flow q = N / T (veh/s; N the
    vehicles whose front reached the loop).
    """

    def __init__(self, lib: ModuleType, dt: float, steps_per_period: int,
                 ids: Sequence[str] = (DOWNSTREAM_LOOP,)) -> None:
        require(steps_per_period >= 1, "steps_per_period", steps_per_period, "at least 1")
        self.lib, self.dt, self.steps_per_period = lib, dt, steps_per_period
        #: the loop's E1s (one per lane; the occupancy is their mean)
        self.ids = tuple(ids)
        self._on: set[str] = set()
        self._reset()

    def _reset(self) -> None:
        self.occupied, self.entered, self.steps = 0.0, 0, 0

    def observe(self, t: float) -> tuple[float, float] | None:
        """Read the step that ended at ``t`` (s); ``(occupancy, flow)`` (fraction, veh/s)
        of the period when it is complete, else None."""
        on, t0 = set(), t - self.dt
        for vid, _length, t_in, t_out, _vtype in _vehicle_data(self.lib, self.ids):
            on.add(vid)
            self.entered += vid not in self._on
            end = t if t_out < 0 else min(t_out, t)
            self.occupied += max(end - max(t_in, t0), 0.0)
        self._on = on
        self.steps += 1
        if self.steps < self.steps_per_period:
            return None
        span = self.steps * self.dt
        out = (self.occupied / len(self.ids) / span, self.entered / span)
        self._reset()
        return out
