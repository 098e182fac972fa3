"""Optional detector realism: a chain of E2 lane-area detectors along ``main``.

One detector per measurement cell. An E2 detector reports every vehicle with any part
inside it, so a vehicle straddling the border of two cells is reported by both and a
naive chain overcounts (about 10 % with 50 m cells on the prototype). :class:`E2Sensor`
reads the chain from downstream to upstream and keeps each vehicle only in the first
(most downstream) detector reporting it: the one holding its front, which is the
convention of :class:`~arzsumo.sumo.measure.MainlineSensor`, so both give the same
densities. Class speeds come from ``vehicle.getSpeed`` of the detected vehicles.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from xml.sax.saxutils import quoteattr

import numpy as np

from arzsumo.errors import require
from arzsumo.io import atomic_file
from arzsumo.sumo.measure import CellData, EdieGrid, MeasurementLog
from arzsumo.sumo.network import MAIN


def detector_ids(n: int) -> list[str]:
    """Ids of the chain, upstream first."""
    return [f"e2_{k:03d}" for k in range(n)]


def write_additional(path: Path, tag: str, elements: list[dict[str, str]]) -> Path:
    """Write a SUMO additional file of ``<tag .../>`` elements (attributes as given),
    atomically, and return its path."""
    lines = ["    <" + tag + " " + " ".join(f"{a}={quoteattr(v)}" for a, v in e.items()) + "/>"
             for e in elements]
    with atomic_file(path) as tmp:
        tmp.write_text("<additional>\n" + "\n".join(lines) + "\n</additional>\n",
                       encoding="utf-8")
    return path


def write_e2_chain(path: Path, length: float, cell_length: float, period: float = 60.0) -> Path:
    """Write an additional file with one E2 detector per cell of ``main_0``."""
    n = round(length / cell_length)
    require(abs(n * cell_length - length) < 1e-9, "cell_length", cell_length,
            f"a length dividing the road length {length} m")
    elements = [{"id": det, "lane": f"{MAIN}_0", "pos": f"{k * cell_length:.3f}",
                 "endPos": f"{(k + 1) * cell_length:.3f}", "period": f"{period:g}",
                 "file": "e2_output.xml"} for k, det in enumerate(detector_ids(n))]
    return write_additional(path, "laneAreaDetector", elements)


class E2Sensor:
    """Edie aggregates from the E2 chain, each vehicle counted once (in its front's cell)."""

    def __init__(self, lib: ModuleType, length: float, cell_length: float, dt: float,
                 steps_per_window: int) -> None:
        self.lib, self.grid = lib, EdieGrid(length, cell_length, dt)
        self.ids = detector_ids(self.grid.n)
        self.steps_per_window = steps_per_window
        self.log = MeasurementLog()
        self.double_counted = 0          # reports dropped as duplicates, over the run

    def counts(self) -> tuple[np.ndarray, np.ndarray, int]:
        """Per-cell (counts, speed sums) of shape (2, cells) now, and duplicates dropped."""
        get_ids = self.lib.lanearea.getLastStepVehicleIDs
        speed = self.lib.vehicle.getSpeed
        n = self.grid.n
        cnt, dist = np.zeros((2, n)), np.zeros((2, n))
        seen: set[str] = set()
        dup = 0
        for k in range(n - 1, -1, -1):
            for v in get_ids(self.ids[k]):
                if v in seen:
                    dup += 1
                    continue
                seen.add(v)
                c = 1 if v.startswith("av") else 0
                cnt[c, k] += 1
                dist[c, k] += speed(v)
        return cnt, dist, dup

    def collect(self, t: float) -> CellData | None:
        """Sample the chain at time ``t`` (s); return a finished window or None."""
        cnt, dist, dup = self.counts()
        self.double_counted += dup
        self.grid.add_binned(cnt, dist)
        if self.grid.steps >= self.steps_per_window:
            data = self.grid.flush(t)
            self.log.append(data)
            return data
        return None
