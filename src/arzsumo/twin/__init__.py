"""The nonlinear PDE twin: a finite-volume solver of the 4x4 mixed-autonomy ARZ model.

Pure math in :mod:`state`, :mod:`flux`, :mod:`source`, :mod:`boundary`, :mod:`initial`,
:mod:`scheme`, :mod:`solver` and :mod:`metrics`; :mod:`run` ties a scenario to a run, :mod:`output`
writes it. Controllers plug in through :mod:`arzsumo.twin.controllers`.
"""

from arzsumo.twin.boundary import Inlet, outlet_flux
from arzsumo.twin.controllers import CONTROLLERS, make_controller, register_controller
from arzsumo.twin.initial import InitialCondition, initial_fields
from arzsumo.twin.metrics import Performance, performance, relative_change
from arzsumo.twin.solver import (
    SolverOptions,
    TwinResult,
    TwinStepper,
    TwinStoppedError,
    simulate,
)

__all__ = [
    "CONTROLLERS",
    "InitialCondition",
    "Inlet",
    "Performance",
    "SolverOptions",
    "TwinResult",
    "TwinStepper",
    "TwinStoppedError",
    "initial_fields",
    "make_controller",
    "outlet_flux",
    "performance",
    "register_controller",
    "relative_change",
    "simulate",
]
