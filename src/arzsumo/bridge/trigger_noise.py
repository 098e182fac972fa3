"""The event trigger's dead band measured on the estimate (``[design] noise_from_estimate``).

Before control starts, a copy of the acting controller is checked on the estimate of the
warm-up's last ``reference_window`` seconds, the nominal plan applied, and the sd of its
continuous output's noise (:func:`arzsumo.control.etc.output_noise_sd`) sizes the dead
band of the controller that will act (paper, defdynamic). docs/design.md, 'Measured on
the estimate'.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence

import numpy as np

from arzsumo.bridge.reference import ReferenceShift
from arzsumo.control.base import Applied, Controller, MacroState
from arzsumo.control.etc import output_noise_sd


def warmup_states(fields: Sequence[np.ndarray], x: np.ndarray, period: float,
                  window: float, shift: ReferenceShift | None) -> list[MacroState]:
    """The estimate of the warm-up's last ``window`` s (``fields``: (4, cells) per period
    of ``period`` s, oldest first) as the controller sees it (``shift`` subtracted), at
    times before the start of control (s, the last one period before 0)."""
    k = max(2, round(window / period))
    tail = list(fields[-k:])
    states = [MacroState(-(len(tail) - i) * period, x, *np.asarray(f, float))
              for i, f in enumerate(tail)]
    return [shift.apply(s) for s in states] if shift else states


def law_output_noise(ctrl: Controller, states: Sequence[MacroState]) -> float:
    """The sd (veh/s) of ``ctrl``'s output noise on ``states``: a copy checked on each with
    the nominal plan applied (U = 0), the noise of its continuous output."""
    probe = copy.deepcopy(ctrl)
    probe.reset()
    for i, state in enumerate(states):
        probe.step(state, Applied(0.0) if i else None)
    return output_noise_sd(np.asarray(probe.log.u_continuous))


def size_dead_band(ctrl: Controller, states: Sequence[MacroState]) -> float | None:
    """Measure the output noise of ``ctrl`` on ``states`` and size its trigger's dead band
    with it; returns the sd (veh/s), None when ``ctrl`` has no trigger or the noise is
    not measurable (the probe runs only for a law with a trigger)."""
    if not ctrl.has_trigger:
        return None
    sd = law_output_noise(ctrl, states)
    if not np.isfinite(sd):
        return None
    return sd if ctrl.set_output_noise(sd) else None
