"""arzsumo: PDE boundary control of mixed-autonomy traffic, from the ARZ model into SUMO.

The public API (``docs/api.md``)::

    import arzsumo

    sc = arzsumo.load_scenario("default")              # a shipped name or a TOML file
    res = arzsumo.run(sc, controller="etc", seed=1)    # SUMO's closed loop -> RunResult
    res.save("results/etc-seed1")                      # what `arzsumo run --out` writes
    twin = arzsumo.twin(sc, controller="etc")          # the PDE twin -> TwinResult
    ev = arzsumo.evaluate(sc, controllers=["open", "etc"], seeds=10)   # paired, 10 seeds
    cal = arzsumo.calibrate(sc, out="runs/cal")        # the diagram and the meter curve

Your own law subclasses :class:`arzsumo.Controller` (one method, ``decide(state) -> U``)
and is passed as ``controller=`` or registered with :func:`arzsumo.register_controller`.

The names are imported on first use, so ``import arzsumo`` stays light (no SUMO, no
pandas) for code that needs one room, such as ``arzsumo.model``.
"""

from __future__ import annotations

from typing import Any

from arzsumo.version import __version__

#: the public names and the module of each (re-exported by :mod:`arzsumo.api` too)
_API = {
    "Applied": "arzsumo.control.base", "Command": "arzsumo.control.base",
    "Controller": "arzsumo.control.base", "MacroState": "arzsumo.control.base",
    "ControllerInputs": "arzsumo.control.registry",
    "ArzsumoError": "arzsumo.errors", "ScenarioError": "arzsumo.errors",
    "Scenario": "arzsumo.scenario", "RunSummary": "arzsumo.outputs.run_summary",
    "EvaluationResult": "arzsumo.sweep.evaluate",
    "RunResult": "arzsumo.api.results", "TwinResult": "arzsumo.api.results",
    "TwinSummary": "arzsumo.api.results",
    "controller_names": "arzsumo.api.controllers",
    "register_controller": "arzsumo.api.controllers",
    "calibrate": "arzsumo.api.calibration",
    "evaluate": "arzsumo.api.evaluation", "load_scenario": "arzsumo.api.scenarios",
    "network_figure": "arzsumo.api.network", "road_geometry": "arzsumo.api.network",
    "prepare": "arzsumo.api.runs", "run": "arzsumo.api.runs", "twin": "arzsumo.api.runs",
}

__all__ = ["__version__", *_API]


def __getattr__(name: str) -> Any:
    if name in _API:
        from importlib import import_module

        value = getattr(import_module(_API[name]), name)
        globals()[name] = value      # once: later lookups do not come here
        return value
    raise AttributeError(f"module 'arzsumo' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*__all__, *(n for n in globals() if n.startswith("__"))})
