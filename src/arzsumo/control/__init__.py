"""Controllers: backstepping kernels and laws, event-triggered control, observers, baselines.

Pure math: no SUMO, no files, no plotting. May import ``model``, ``units`` and ``errors``
(contracts in ``pyproject.toml``, checked by ``lint-imports``).
"""

from arzsumo.control.base import ConstantControl, Controller, ControlLog, MacroState, OpenLoop
from arzsumo.control.registry import CONTROLLERS, PDE_CONTROLLERS, make_controller

__all__ = [
    "CONTROLLERS",
    "PDE_CONTROLLERS",
    "ConstantControl",
    "ControlLog",
    "Controller",
    "MacroState",
    "OpenLoop",
    "make_controller",
]
