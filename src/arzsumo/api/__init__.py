"""The public API, re-exported by :mod:`arzsumo` (``arzsumo.run``, ``arzsumo.twin``, ...).

Each module keeps its ``__all__``; this package gathers them. The CLI calls these
functions: every check a command makes is made here, so a Python caller gets it too.
"""

from arzsumo.api.controllers import controller_names, register_controller
from arzsumo.api.evaluate import evaluate
from arzsumo.api.network import network_figure, road_geometry
from arzsumo.api.results import RunResult, TwinResult, TwinSummary
from arzsumo.api.runs import prepare, run, twin
from arzsumo.api.scenarios import load_scenario
from arzsumo.control.base import Applied, Command, Controller, MacroState
from arzsumo.control.registry import ControllerInputs
from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.outputs.run_summary import RunSummary
from arzsumo.scenario import Scenario
from arzsumo.sweep.evaluate import EvaluationResult

__all__ = ["Applied", "ArzsumoError", "Command", "Controller", "ControllerInputs",
           "EvaluationResult", "MacroState", "RunResult", "RunSummary", "Scenario",
           "ScenarioError", "TwinResult", "TwinSummary", "controller_names", "evaluate",
           "load_scenario", "network_figure", "prepare", "register_controller",
           "road_geometry", "run", "twin"]
