"""Lateral positions of the vehicles on ``main``, once per control period.

Wave measures per lateral file (:mod:`arzsumo.evaluation.waves`) need each vehicle's
lateral offset. It costs one libsumo call per vehicle, so it is read at a control
period's last step only, beside what the mainline sensor read at that step
(:class:`~arzsumo.sumo.measure.MainlineSensor`), and only during the control window.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import numpy as np


@dataclass(frozen=True)
class LateralRecord:
    """Per-period snapshots of the vehicles on ``main``, concatenated (SI).

    ``t`` (periods,) the snapshot times, s of simulation time; ``counts`` (periods,) the
    vehicles in each snapshot; ``pos`` (m from the inlet), ``speed`` (m/s), ``lat``
    (lateral offset from the lane centre, m, > 0 to the left) and ``av`` (AV mask), one
    entry per vehicle sample, snapshot after snapshot.
    """

    t: np.ndarray
    counts: np.ndarray
    pos: np.ndarray
    speed: np.ndarray
    lat: np.ndarray
    av: np.ndarray

    @property
    def period(self) -> np.ndarray:
        """Snapshot index (0-based) of each sample."""
        return np.repeat(np.arange(self.counts.size), self.counts)


class LateralSampler:
    """Keeps one snapshot per call: the lateral offsets of the given vehicles, read now."""

    def __init__(self, lib: ModuleType) -> None:
        self.lib = lib
        self._t: list[float] = []
        self._parts: list[tuple[np.ndarray, ...]] = []

    def sample(self, t: float, ids: tuple[str, ...], pos: np.ndarray, speed: np.ndarray,
               av: np.ndarray) -> None:
        """Snapshot at ``t`` (s) of the vehicles ``ids`` with their positions (m), speeds
        (m/s) and AV mask, as read at this step; adds their lateral offsets (m)."""
        lat = np.fromiter(map(self.lib.vehicle.getLateralLanePosition, ids), float,
                          len(ids))
        self._t.append(float(t))
        self._parts.append((np.asarray(pos, float), np.asarray(speed, float), lat,
                            np.asarray(av, bool)))

    def record(self) -> LateralRecord:
        """Everything sampled so far."""
        counts = np.array([p[0].size for p in self._parts], np.intp)
        cols = [np.concatenate([p[k] for p in self._parts]) if self._parts else
                np.empty(0, bool if k == 3 else float) for k in range(4)]
        return LateralRecord(np.array(self._t, float), counts, *cols)
