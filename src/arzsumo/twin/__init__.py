"""The nonlinear PDE twin: a finite-volume solver of the 4x4 mixed-autonomy ARZ model.

Numerics in :mod:`state`, :mod:`flux`, :mod:`source`, :mod:`boundary`, :mod:`initial`,
:mod:`scheme`, :mod:`solver` and :mod:`metrics`: they may import only ``control``,
``model``, ``units`` and ``errors`` (the "math" contract in ``pyproject.toml``). The
scenario wiring, :mod:`config` (the ``[twin]`` and ``[initial]`` tables), :mod:`controllers`
(the registry; kernels from ``kernel_cache``) and :mod:`run` (a scenario to a run), may also
import ``scenarios`` and ``kernel_cache``. The twin writes no files: runs are written by
:mod:`arzsumo.outputs.twin`; paper reproduction lives in :mod:`arzsumo.studies.paper`.
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
