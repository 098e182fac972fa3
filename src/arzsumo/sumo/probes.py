"""AV probes: the AVs on ``main`` as mobile sensors, once per control period.

At the last step of each control period :class:`AvProbes` reports the positions (front,
m from x = 0, in [0, L]) and speeds (m/s) of the reporting AVs on ``main`` as a
:class:`~arzsumo.estimate.observations.ProbeObservation` of class ``a``. It reads them
from the per-step sample the closed loop's sensor already takes
(:meth:`arzsumo.sumo.measure.MainlineSensor.sample`: no extra libsumo call), or, alone,
with :meth:`AvProbes.read`.

Which AVs report is drawn once per vehicle, from its id and a seed: an AV reports when
``blake2b(f"{seed}:{id}") / 2^64 < share`` (a fleet in which a share of the AVs is
equipped; an equipped AV reports on every period of its trip). The draw depends on
nothing else, so it is reproducible for a seed and independent of SUMO's own seed; two
seeds draw independent fleets (crc32 did not: it is linear, and two seeds drew disjoint
fleets).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from types import ModuleType

import numpy as np

from arzsumo.errors import ScenarioError, require
from arzsumo.estimate.observations import ProbeNoise, ProbeObservation
from arzsumo.sumo.measure import is_av
from arzsumo.sumo.network import MAIN


def reports(vid: str, share: float, seed: int) -> bool:
    """Whether the AV ``vid`` is a probe at ``share`` under ``seed``."""
    if share >= 1.0:
        return True
    digest = hashlib.blake2b(f"{seed}:{vid}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "big") < share * 2.0**64


class AvProbes:
    """The reporting AVs on ``main``, once per period.

    Parameters
    ----------
    share : float
        Share of the AVs that report, in (0, 1].
    seed : int
        Seed of the draw of reporting AVs.
    noise : ProbeNoise
        Noise model attached to the records (for the estimators).
    """

    def __init__(self, share: float = 1.0, seed: int = 1,
                 noise: ProbeNoise | None = None) -> None:
        require(isinstance(share, int | float) and math.isfinite(share) and 0 < share <= 1,
                "av_probe_share", share, "a fraction in (0, 1]", ScenarioError)
        self.share, self.seed = float(share), seed
        self.noise = noise or ProbeNoise()
        self._drawn: dict[str, bool] = {}
        self.records: list[ProbeObservation] = []

    def mask(self, ids: Sequence[str]) -> np.ndarray:
        """Which of the vehicles ``ids`` (all AVs) report."""
        drawn = self._drawn
        out = np.empty(len(ids), bool)
        for k, vid in enumerate(ids):
            hit = drawn.get(vid)
            if hit is None:
                hit = drawn[vid] = reports(vid, self.share, self.seed)
            out[k] = hit
        return out

    def observe(self, t: float, ids: Sequence[str], pos: np.ndarray, speed: np.ndarray,
                av: np.ndarray) -> ProbeObservation:
        """The record at ``t`` (s) from one step's sample of ``main``.

        ``ids``, ``pos`` (m), ``speed`` (m/s) and ``av`` (AV mask) describe every vehicle
        on ``main`` (as :meth:`~arzsumo.sumo.measure.MainlineSensor.sample` returns them).
        """
        av = np.asarray(av, bool)
        av_ids = [vid for vid, a in zip(ids, av, strict=True) if a]
        keep = self.mask(av_ids)
        obs = ProbeObservation(float(t), "a", np.asarray(pos, float)[av][keep],
                               np.asarray(speed, float)[av][keep], self.share, self.noise)
        self.records.append(obs)
        return obs

    def read(self, lib: ModuleType, t: float) -> ProbeObservation:
        """The record at ``t`` (s), read from the open run ``lib`` (AVs only)."""
        ids = [v for v in lib.edge.getLastStepVehicleIDs(MAIN) if v.startswith("av")]
        keep = [v for v, k in zip(ids, self.mask(ids), strict=True) if k]
        get_pos, get_speed = lib.vehicle.getLanePosition, lib.vehicle.getSpeed
        pos = np.fromiter(map(get_pos, keep), float, len(keep))
        speed = np.fromiter(map(get_speed, keep), float, len(keep))
        return self.observe(t, keep, pos, speed, is_av(keep))
