"""The state a PDE controller regulates to: the model's equilibrium, or the mean state SUMO
held in the warm-up (``[estimation] reference``, docs/scenarios.md).

Where the model's fundamental diagram and SUMO disagree about the speed at SUMO's
densities, a state SUMO holds for minutes under the nominal plan is a constant deviation
to the law (paper, eq. ``control_law``), answered with a constant U (measured:
research/readings/ablation_in_sumo.md, "The mismatches, measured"). With
``reference = "warmup"`` that state gets U = 0; the laws being linear in the fields
(:class:`arzsumo.control.backstepping.StateMap`), this subtracts the law's answer to the
constant offset.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from arzsumo.control.base import MacroState
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import VARIABLES
from arzsumo.scenario.estimation import REFERENCES


@dataclass(frozen=True)
class ReferenceShift:
    """Per-cell offset (4, n) subtracted from the fields a controller is checked on."""

    offset: np.ndarray

    def apply(self, state: MacroState) -> MacroState:
        """``state`` with the offset subtracted (occupancy and time unchanged)."""
        o = self.offset
        return replace(state, rho_h=state.rho_h - o[0], v_h=state.v_h - o[1],
                       rho_a=state.rho_a - o[2], v_a=state.v_a - o[3])

    def means(self) -> dict[str, float]:
        """The offset's mean over the cells per variable (SI)."""
        return {name: float(np.mean(self.offset[k])) for k, name in enumerate(VARIABLES)}


def reference_shift(reference: str, warm_fields: Sequence[np.ndarray], eq: Equilibrium,
                    window: float, period: float) -> ReferenceShift:
    """The shift of ``reference`` (:data:`REFERENCES`): zero for ``"equilibrium"``; for
    ``"warmup"`` the mean of the last ``window`` s of ``warm_fields`` (the estimate (4, n)
    of every warm-up period of ``period`` s, oldest first; one at least) minus ``eq``."""
    if reference not in REFERENCES:
        raise ValueError(f"reference {reference!r}: one of {REFERENCES}")
    n = np.asarray(warm_fields[-1]).shape[1]
    if reference == "equilibrium":
        return ReferenceShift(np.zeros((4, n)))
    k = max(1, math.ceil(window / period - 1e-9))
    mean = np.nanmean(np.asarray(warm_fields[-k:], float), axis=0)
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
    return ReferenceShift(np.where(np.isfinite(mean), mean - star, 0.0))
