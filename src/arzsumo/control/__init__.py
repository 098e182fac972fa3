"""Controllers: backstepping kernels and laws, event-triggered control, observers, baselines.

Pure math: no SUMO, no files, no plotting. May import ``model``, ``units`` and ``errors``
(contracts in ``pyproject.toml``, checked by ``lint-imports``).
"""

from arzsumo.control.base import ConstantControl, Controller, ControlLog, MacroState, OpenLoop
from arzsumo.control.registry import (
    controller_names,
    controller_spec,
    is_pde,
    pde_controller_names,
)

__all__ = ["ConstantControl", "ControlLog", "Controller", "MacroState", "OpenLoop",
           "controller_names", "controller_spec", "is_pde", "pde_controller_names"]
