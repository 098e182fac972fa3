"""Which sensors a run has: :class:`SensorLayout`, chosen per scenario (``[sensing]``).

Kinds, combinable (docs/sumo.md, "Sensing layouts"): ``"probe"``, every vehicle on
``main`` in cells and periods (:class:`~arzsumo.sumo.measure.MainlineSensor`); ``"loops"``,
E1 loop stations (:mod:`arzsumo.sumo.loops`); ``"av_probes"``, the positions and speeds of
a share of the AVs on ``main`` (:mod:`arzsumo.sumo.probes`). The scenario keys are listed,
with their units, in :mod:`arzsumo.scenario.sensing`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import ScenarioError, require
from arzsumo.sumo.loops import LOOP_SPEEDS, placed_positions

KINDS = ("probe", "loops", "av_probes")


def _check(ok: bool, field: str, value: object, allowed: str) -> None:
    require(ok, field, value, allowed, ScenarioError)


@dataclass(frozen=True)
class SensorLayout:
    """The sensors of a run (SI).

    ``kinds``: one or more of :data:`KINDS`, each once; ``loop_spacing``: distance between
    loop stations, m (> 0: stations at 0, s, 2s, ... and at L), or ``loop_positions``, m
    in [0, L] (neither: the two boundaries); ``av_probe_share``: share of the AVs that
    report, in (0, 1], drawn with ``av_probe_seed`` (>= 0); ``loop_speed``: the time-mean
    or harmonic mean of the spot speeds (:mod:`arzsumo.sumo.loops`).
    """

    kinds: tuple[str, ...] = ("probe",)
    loop_spacing: float | None = None
    loop_positions: tuple[float, ...] = ()
    av_probe_share: float = 1.0
    av_probe_seed: int = 1
    loop_speed: str = "time_mean"

    def __post_init__(self) -> None:
        kinds = self.kinds
        _check(isinstance(kinds, tuple) and len(kinds) >= 1
               and all(isinstance(k, str) and k in KINDS for k in kinds), "kinds",
               list(kinds) if isinstance(kinds, tuple) else kinds,
               f"a non-empty list of {', '.join(KINDS)}")
        _check(len(set(kinds)) == len(kinds), "kinds", list(kinds), "each kind once")
        s = self.loop_spacing
        _check(s is None or (isinstance(s, int | float) and math.isfinite(s) and s > 0),
               "loop_spacing", s, "a distance > 0 m")
        _check(s is None or not self.loop_positions, "loop_spacing", s,
               "either a spacing or positions, not both")
        _check(all(isinstance(x, int | float) and math.isfinite(x)
                   for x in self.loop_positions), "loop_positions",
               list(self.loop_positions), "finite positions in m")
        _check("loops" in kinds or (s is None and not self.loop_positions),
               "loop_spacing" if s is not None else "loop_positions",
               s if s is not None else list(self.loop_positions),
               "only with kinds including \"loops\"")
        p = self.av_probe_share
        _check(isinstance(p, int | float) and math.isfinite(p) and 0 < p <= 1,
               "av_probe_share", p, "a fraction in (0, 1]")
        _check(isinstance(self.av_probe_seed, int) and not isinstance(self.av_probe_seed, bool)
               and self.av_probe_seed >= 0, "av_probe_seed", self.av_probe_seed,
               "an integer >= 0")
        _check(self.loop_speed in LOOP_SPEEDS, "loop_speed", self.loop_speed,
               f"one of {', '.join(LOOP_SPEEDS)}")

    @property
    def loops(self) -> bool:
        """Has loop stations."""
        return "loops" in self.kinds

    @property
    def av_probes(self) -> bool:
        """Has AV probes."""
        return "av_probes" in self.kinds

    def loop_x(self, length: float) -> tuple[float, ...]:
        """Station positions asked for on a section of ``length`` L (m), sorted; () without
        loops. Positions outside [0, L] are refused (one line)."""
        if not self.loops:
            return ()
        if self.loop_positions:
            x = np.asarray(self.loop_positions, float)
        elif self.loop_spacing is not None:
            x = np.arange(0.0, length, self.loop_spacing)
            x = np.append(x[x < length - 1e-9], length)
        else:
            x = np.array([0.0, length])
        placed_positions(x, length)             # in [0, L], distinct once placed
        return tuple(float(v) for v in np.sort(x))
