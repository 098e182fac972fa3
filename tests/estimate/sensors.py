"""Sensor data sampled from the synthetic truth, shared by the estimator tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from arzsumo.estimate.observations import (
    LoopNoise,
    LoopObservation,
    ProbeNoise,
    ProbeObservation,
)
from arzsumo.estimate.synthetic import interpolate_loops, sample_loops, sample_probes

#: Loop stations every 250 m, both boundaries included.
LOOPS_X = np.arange(0.0, 1000.0 + 1.0, 250.0)
#: The estimators' grid: the controller's 50 m cells.
CELLS = 20
#: Scored from this time on (s): the estimators' spin-up is left out.
SCORED_FROM = 60


@dataclass(frozen=True)
class Sensors:
    loops: list[LoopObservation]
    probes: list[ProbeObservation]
    x: np.ndarray              # estimator cell centres, m
    truth: np.ndarray          # (n_t, 4, CELLS) truth as cell means
    star: np.ndarray           # (4,) equilibrium (rho_h, v_h, rho_a, v_a)

    def rmse(self, est: np.ndarray) -> np.ndarray:
        """RMSE (4,) of fields (n_t, 4, CELLS) over cells and scored times."""
        err = est[SCORED_FROM:] - self.truth[SCORED_FROM:]
        return np.sqrt(np.nanmean(err ** 2, axis=(0, 2)))

    def interpolation(self) -> np.ndarray:
        """The baseline: linear interpolation between the stations, every period."""
        return np.array([interpolate_loops(obs, self.x) for obs in self.loops])


def sample(truth, seed: int = 1, share: float = 1.0) -> Sensors:
    """Loops (default noise: 0.1 veh/s, 1.5 m/s, 8 veh/km) every second and all AVs as
    probes (speed noise 1 m/s), from the truth's 1 s snapshots."""
    rng = np.random.default_rng(seed)
    eq = truth.eq
    loops = [sample_loops(truth.x, f, LOOPS_X, float(t), 1.0, LoopNoise(), rng)
             for t, f in zip(truth.t, truth.fields, strict=True)]
    probes = [sample_probes(truth.x, f, "a", share, float(t), ProbeNoise(), rng)
              for t, f in zip(truth.t, truth.fields, strict=True)]
    x = (np.arange(CELLS) + 0.5) * eq.params.length / CELLS
    return Sensors(loops, probes, x, truth.coarse(CELLS),
                   np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a]))
