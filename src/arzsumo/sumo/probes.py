"""AV probes: the AVs on ``main`` as mobile sensors, once per control period.

At the last step of each control period :class:`AvProbes` reports the positions (front,
m from x = 0) and speeds (m/s) of the reporting AVs on ``main`` as a
:class:`~arzsumo.estimate.observations.ProbeObservation` of class ``a``, from the sample
the sensor already takes (:meth:`arzsumo.sumo.measure.MainlineSensor.sample`) or, alone,
with :meth:`AvProbes.read`. An AV reports when ``blake2b(f"{seed}:{id}") / 2^64 < share``:
a fixed equipped fleet, reproducible for a seed and independent of SUMO's own
(docs/sumo.md, "Sensing layouts").
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from types import ModuleType

import numpy as np

from arzsumo.errors import ScenarioError, require
from arzsumo.estimate.observations import ProbeNoise, ProbeObservation
from arzsumo.sumo.network import MAIN


def reports(vid: str, share: float, seed: int) -> bool:
    """Whether the AV ``vid`` is a probe at ``share`` under ``seed``."""
    if share >= 1.0:
        return True
    digest = hashlib.blake2b(f"{seed}:{vid}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "big") < share * 2.0**64


class AvProbes:
    """The reporting AVs on ``main``, once per period: a ``share`` in (0, 1] of them, drawn
    with ``seed``; ``noise`` is attached to the records (for the estimators)."""

    def __init__(self, share: float = 1.0, seed: int = 1,
                 noise: ProbeNoise | None = None) -> None:
        require(isinstance(share, int | float) and math.isfinite(share) and 0 < share <= 1,
                "av_probe_share", share, "a fraction in (0, 1]", ScenarioError)
        self.share, self.seed = float(share), seed
        self.noise = noise or ProbeNoise()
        self._drawn: dict[str, bool] = {}

    def mask(self, ids: Sequence[str]) -> np.ndarray:
        """Which of the vehicles ``ids`` (all AVs) report."""
        drawn = self._drawn
        for vid in ids:
            if vid not in drawn:
                drawn[vid] = reports(vid, self.share, self.seed)
        return np.fromiter(map(drawn.__getitem__, ids), bool, len(ids))

    def observe(self, t: float, ids: Sequence[str], pos: np.ndarray, speed: np.ndarray,
                av: np.ndarray) -> ProbeObservation:
        """The record at ``t`` (s) from one step's sample of every vehicle on ``main``:
        ``ids``, ``pos`` (m), ``speed`` (m/s) and ``av`` (AV mask), as
        :meth:`~arzsumo.sumo.measure.MainlineSensor.sample` returns them."""
        av = np.asarray(av, bool)
        av_ids = [vid for vid, a in zip(ids, av, strict=True) if a]
        keep = self.mask(av_ids)
        return ProbeObservation(float(t), "a", np.asarray(pos, float)[av][keep],
                                np.asarray(speed, float)[av][keep], self.share, self.noise)

    def read(self, lib: ModuleType, t: float) -> ProbeObservation:
        """The record at ``t`` (s), read from the open run ``lib`` (AVs only)."""
        ids = [v for v in lib.edge.getLastStepVehicleIDs(MAIN) if v.startswith("av")]
        keep = [v for v, k in zip(ids, self.mask(ids), strict=True) if k]
        pos = np.fromiter(map(lib.vehicle.getLanePosition, keep), float, len(keep))
        speed = np.fromiter(map(lib.vehicle.getSpeed, keep), float, len(keep))
        return self.observe(t, keep, pos, speed, np.ones(len(keep), bool))   # AVs only
