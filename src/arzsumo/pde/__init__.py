"""The nonlinear PDE twin: a finite-volume solver of the 4x4 mixed-autonomy ARZ model.

Numerics only (its modules: docs/twin.md, "Pieces"); they may import only ``control``,
``model``, ``units`` and ``errors`` (the "math" contract in ``pyproject.toml``).
"""

from arzsumo.pde.boundary import Inlet, outlet_flux
from arzsumo.pde.initial import InitialCondition, initial_fields
from arzsumo.pde.solver import (
    SolverOptions,
    TwinStepper,
    TwinStoppedError,
    simulate,
)

__all__ = [
    "InitialCondition",
    "Inlet",
    "SolverOptions",
    "TwinStepper",
    "TwinStoppedError",
    "initial_fields",
    "outlet_flux",
    "simulate",
]
