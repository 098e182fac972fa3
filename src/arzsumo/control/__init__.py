"""Controllers: backstepping kernels and laws, event-triggered control, observers, baselines.

Pure math: no SUMO, no files, no plotting.
"""

from arzsumo.control.base import ConstantControl, Controller, ControlLog, MacroState, OpenLoop

__all__ = ["ConstantControl", "ControlLog", "Controller", "MacroState", "OpenLoop"]
