"""The estimation stage of the closed loop: a period's measurement to a :class:`MacroState`.

:class:`FundamentalDiagramFill` takes the Edie cells as they are, cells no vehicle of a
class visited at the equilibrium speed Ve of their densities (paper, eq. ``Ve``); the
sparse-sensor estimators are in :mod:`arzsumo.bridge.estimators`.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from arzsumo.control.base import MacroState
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.model.params import ModelParameters
from arzsumo.sumo.sensor import PeriodMeasurement


def fill_speeds(params: ModelParameters, rho_h: np.ndarray, v_h: np.ndarray,
                rho_a: np.ndarray, v_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Speeds (m/s) with empty cells (NaN) replaced by Ve at the cell's densities (veh/m)."""
    ve_h, ve_a = equilibrium_speeds(params, rho_h, rho_a)
    return np.where(np.isfinite(v_h), v_h, ve_h), np.where(np.isfinite(v_a), v_a, ve_a)


class Estimator(Protocol):
    """Measurement of one period -> the state the controller is checked on."""

    def estimate(self, measurement: PeriodMeasurement, t: float) -> MacroState:
        """The state at control time ``t`` (s from the start of control)."""
        ...


class FundamentalDiagramFill:
    """Edie cells as measured; empty cells get Ve at their densities (no filtering)."""

    def __init__(self, params: ModelParameters) -> None:
        self.params = params

    def estimate(self, measurement: PeriodMeasurement, t: float) -> MacroState:
        cells = measurement.cells
        v_h, v_a = fill_speeds(self.params, cells.rho_h, cells.v_h, cells.rho_a, cells.v_a)
        return MacroState(t, cells.x, cells.rho_h, v_h, cells.rho_a, v_a,
                          measurement.occupancy_out)
