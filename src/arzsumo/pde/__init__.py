"""The nonlinear PDE twin: a finite-volume solver of the 4x4 mixed-autonomy ARZ model.

Numerics only, in :mod:`state`, :mod:`flux`, :mod:`source`, :mod:`boundary`,
:mod:`initial`, :mod:`scheme`, :mod:`solver`, :mod:`metrics` and :mod:`supply` (a
cell's receiving capacity, for a bounded inlet flux): they may import only
``control``, ``model``, ``units`` and ``errors`` (the "math" contract in
``pyproject.toml``). Scenarios become twin runs elsewhere: the ``[twin]`` and
``[initial]`` sections in :mod:`arzsumo.scenario.twin`, the controllers in
:mod:`arzsumo.control.registry`, a run in :mod:`arzsumo.engines.twin`; runs are written by
:mod:`arzsumo.outputs.twin`; paper reproduction lives in :mod:`arzsumo.workflows.paper`.
"""

from arzsumo.pde.boundary import Inlet, outlet_flux
from arzsumo.pde.initial import InitialCondition, initial_fields
from arzsumo.pde.metrics import Performance, performance, relative_change
from arzsumo.pde.solver import (
    SolverOptions,
    TwinResult,
    TwinStepper,
    TwinStoppedError,
    simulate,
)

__all__ = [
    "InitialCondition",
    "Inlet",
    "Performance",
    "SolverOptions",
    "TwinResult",
    "TwinStepper",
    "TwinStoppedError",
    "initial_fields",
    "outlet_flux",
    "performance",
    "relative_change",
    "simulate",
]
