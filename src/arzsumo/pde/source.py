"""Relaxation source, integrated exactly (paper, section 2; docs/twin.md, "Source").

In conservative variables the source is (0, -y_h / tau_h, 0, -y_a / tau_a) and leaves the
densities (hence AO and Ve_i) unchanged, so y_i(t + dt) = exp(-dt / tau_i) y_i(t) exactly:
unconditionally stable. The twin applies it by Strang splitting.
"""

from __future__ import annotations

import math

import numpy as np

from arzsumo.model.params import ModelParameters
from arzsumo.pde.state import Y_A, Y_H


def relax(p: ModelParameters, q: np.ndarray, dt: float) -> np.ndarray:
    """Exact solution of q_t = S(q) over ``dt`` >= 0 seconds for conserved ``q`` (4, ...);
    returns a new array."""
    out = q.copy()
    out[Y_H] *= math.exp(-dt / p.tau_h)
    out[Y_A] *= math.exp(-dt / p.tau_a)
    return out
