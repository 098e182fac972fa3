"""A controller that sees the state through white measurement noise.

In SUMO the PDE laws act on an estimate of the section's fields whose fast noise the
nonlinear twin does not have. :class:`NoisyState` puts that noise into the twin: at every
check it multiplies each field of each cell by ``1 + relative_sd * n`` (``n`` standard
normal, independent between fields, cells and checks; densities kept >= 0) and hands the
result to the wrapped controller. The law's output then carries noise as it does in SUMO,
so the event trigger of the ETC (paper, section 4, label defdynamic) can be judged on a
state with a known noise level.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from arzsumo.control.base import Controller, MacroState
from arzsumo.errors import require


class NoisyState(Controller):
    """``inner`` checked on the state with relative white noise of sd ``relative_sd``
    (a fraction, e.g. 0.02 for 2 %) per field, cell and check, from ``seed``.

    The log is the wrapped controller's; :meth:`reset` restarts the noise, so a run
    repeated with the same seed sees the same noise.
    """

    def __init__(self, inner: Controller, relative_sd: float, seed: int) -> None:
        require(math.isfinite(relative_sd) and relative_sd >= 0, "relative_sd", relative_sd,
                "a number >= 0")
        super().__init__()
        self.inner, self.relative_sd, self.seed = inner, float(relative_sd), int(seed)
        self.name = inner.name
        self.reset()

    def reset(self) -> None:
        self.inner.reset()
        self.log = self.inner.log
        self.rng = np.random.default_rng(self.seed)

    def noisy(self, state: MacroState) -> MacroState:
        """``state`` with this check's noise on every field."""
        shape = (4, *np.shape(state.rho_h))
        factor = 1.0 + self.relative_sd * self.rng.standard_normal(shape)
        return replace(state, rho_h=np.maximum(state.rho_h * factor[0], 0.0),
                       v_h=state.v_h * factor[1],
                       rho_a=np.maximum(state.rho_a * factor[2], 0.0),
                       v_a=state.v_a * factor[3])

    def decide(self, state: MacroState) -> float:
        return self.inner.check(self.noisy(state))

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        self.inner.applied(u, lower, upper)

    def actuated(self, u: float) -> None:
        self.inner.actuated(u)

    @property
    def has_trigger(self) -> bool:
        """The wrapped law's."""
        return self.inner.has_trigger

    def set_output_noise(self, sd: float) -> bool:
        """Handed to the wrapped law (its trigger's dead band; veh/s)."""
        return self.inner.set_output_noise(sd)
