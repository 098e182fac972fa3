"""Stage 1 of ``arzsumo identify --diagram FAMILY``: the diagram from the runs' windows.

From each open-loop run's window (its stationary states): the Edie block states
(:func:`arzsumo.identify.diagram.block_states`, 100 m x 30 s blocks of the 50 m / 1 s
cells) and each class's upstream wave speed, read by the premise's reader
(:func:`arzsumo.evaluation.travel.wave_speed`). :func:`fit_stage_one` then fits the
family's diagram with the wave speed as a residual of its own; stage 2 is
:func:`arzsumo.identify.identify` with ``which = ("tau_h", "tau_a")``.
``docs/identify.md``, 'Two stages'.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from arzsumo.errors import ArzsumoError
from arzsumo.evaluation.travel import wave_speed
from arzsumo.identify.data import ReplayData
from arzsumo.identify.diagram import (
    DiagramFit,
    StationaryStates,
    block_states,
    fit_diagram,
)
from arzsumo.identify.objective import DEFAULT_BOUNDS
from arzsumo.model.fd import area_occupancy
from arzsumo.model.params import FAMILIES, ModelParameters
from arzsumo.scenario import Scenario
from arzsumo.units import ms_to_kmh

#: cells and periods of a stationary block (50 m cells, 1 s periods: 100 m x 30 s)
BLOCK_CELLS, BLOCK_PERIODS = 2, 30
#: the relaxation times stage 2 fits
STAGE_TWO = ("tau_h", "tau_a")


@dataclass(frozen=True)
class WaveReading:
    """The classes' upstream wave speeds of a set of runs (m/s; NaN where unresolved),
    per run and their mean over the runs that resolved one."""

    per_run: dict[str, tuple[float, ...]]

    def mean(self, cls: str) -> float:
        """Mean over runs of class ``cls`` ("h" or "a"), m/s."""
        values = [v for v in self.per_run[cls] if math.isfinite(v)]
        return float(np.mean(values)) if values else math.nan

    @property
    def stream(self) -> float:
        """The mean of both classes' means: the one target lambda_4 is fitted to, m/s."""
        return float(np.nanmean([self.mean("h"), self.mean("a")]))


def read_waves(datasets: Sequence[ReplayData]) -> WaveReading:
    """Each run's class wave speeds from its speed fields (the premise's reader)."""
    out: dict[str, list[float]] = {"h": [], "a": []}
    for d in datasets:
        dt, dx = float(np.median(np.diff(d.t))), float(np.median(np.diff(d.x)))
        for cls, row in (("h", 1), ("a", 3)):
            try:
                out[cls].append(wave_speed(np.asarray(d.fields)[:, row, :], dt, dx).speed)
            except ArzsumoError:
                out[cls].append(math.nan)
    return WaveReading({k: tuple(v) for k, v in out.items()})


def stationary_states(datasets: Sequence[ReplayData]) -> StationaryStates:
    """The block states of every run's window, labelled by run."""
    return StationaryStates.concat([block_states(d, BLOCK_CELLS, BLOCK_PERIODS)
                                    for d in datasets])


def diagram_guess(sc: Scenario, family: str, states: StationaryStates,
                  c: float) -> ModelParameters:
    """The start of stage 1: ``sc``'s model on ``family``, its free-flow speeds the
    vehicle types' largest speeds, wave speeds |c|, jam occupancies 20 % above the
    largest observed block AO (within the bounds)."""
    if family not in FAMILIES:
        raise ArzsumoError(f"--diagram = {family} is not allowed: one of "
                           f"{', '.join(FAMILIES)}")
    p, cfg = sc.params, sc.sumo
    ao = float(np.max(area_occupancy(p, states.rho_h, states.rho_a)))
    jam = min(1.0, max(1.2 * ao, DEFAULT_BOUNDS["ao_max_h"][0]))
    changes: dict[str, float | str] = {
        "family": family, "ao_max_h": jam, "ao_max_a": jam,
        "v_free_h": cfg.hv_max_speed or p.v_free_h, "v_free_a": cfg.av_max_speed or p.v_free_a}
    if family == "newell":
        w = min(max(abs(c), 1.5), 29.0) if math.isfinite(c) else 9.0
        changes.update(wave_speed_h=w, wave_speed_a=w)
    return replace(p, **changes)


def fit_stage_one(sc: Scenario, family: str, train: Sequence[ReplayData],
                  operating_point: tuple[float, float], *, wave: float | None = None,
                  wave_weight: float = 1.0, bootstrap: int = 0, floor: float | None = None
                  ) -> tuple[DiagramFit, WaveReading, StationaryStates]:
    """Stage 1 on the training runs: the fit, the wave reading and the blocks used.

    ``wave`` (m/s) replaces the measured target where given (``--wave-speed-kmh``);
    ``floor`` is the least jam occupancy (:func:`~arzsumo.identify.diagram.fit_diagram`).
    """
    states = stationary_states(train)
    reading = read_waves(train)
    target = wave if wave is not None else reading.stream
    if not (math.isfinite(target) and target < 0):
        raise ArzsumoError(f"stage 1 needs an upstream wave speed; the training runs read "
                           f"{ms_to_kmh(target):+.1f} km/h; allowed: runs whose waves travel "
                           "upstream, or --wave-speed-kmh")
    guess = diagram_guess(sc, family, states, target)
    fit = fit_diagram(guess, states, target, operating_point, wave_weight=wave_weight,
                      bootstrap=bootstrap, floor=floor)
    return fit, reading, states


@dataclass(frozen=True)
class StageOne:
    """Stage 1's fit, the blocks it used, and the wave readings of both run sets."""

    fit: DiagramFit
    states: StationaryStates
    waves: dict[str, WaveReading]

    def wave_gaps(self, role: str, lambda_4: float) -> dict[str, float]:
        """|lambda_4 - c| / |c| per class against the ``role`` runs' reading c."""
        reading = self.waves[role]
        return {cls: abs(lambda_4 - reading.mean(cls)) / abs(reading.mean(cls))
                for cls in ("h", "a")}

    def as_dict(self, lambda_4: dict[str, float]) -> dict[str, object]:
        """Plain numbers (SI): the fit, the readings and the gaps at ``lambda_4`` (the
        final model's, per role, m/s)."""
        return {"fit": self.fit.as_dict(), "blocks": self.states.size,
                "waves": {role: {"per_run": r.per_run, "h": r.mean("h"), "a": r.mean("a")}
                          for role, r in self.waves.items()},
                "lambda_4": lambda_4,
                "wave_gap": {role: self.wave_gaps(role, lam)
                             for role, lam in lambda_4.items()}}
