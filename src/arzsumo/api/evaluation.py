"""Controllers compared on the same SUMO seeds, paired against the open loop
(:func:`evaluate`; ``arzsumo evaluate`` calls it)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from numbers import Integral
from pathlib import Path

import numpy as np

from arzsumo.api.controllers import ControllerLike, controller_name
from arzsumo.api.scenarios import load_scenario, scenario_file
from arzsumo.argtypes import SEED_LIMIT
from arzsumo.bridge.session import API_NAMES, check_warmup
from arzsumo.control.registry import default_controllers
from arzsumo.errors import ScenarioError
from arzsumo.scenario import Scenario
from arzsumo.sweep.evaluate import EvaluationResult, run_evaluation


def seed_list(seeds: int | Sequence[int], start: int = 1) -> list[int]:
    """The seeds: a count N (``start``, ..., ``start`` + N - 1) or the seeds themselves."""
    if isinstance(seeds, bool | np.bool_):
        raise ScenarioError(f"seeds = {seeds!r} is not allowed: a count >= 1 or a list of "
                            "seeds")
    values = list(range(start, start + int(seeds))) if isinstance(seeds, Integral) \
        else list(seeds)
    bad = [s for s in values if isinstance(s, bool | np.bool_) or not isinstance(s, Integral)
           or not 0 <= s < SEED_LIMIT]
    values = [int(s) for s in values]
    if not values or bad or len(set(values)) != len(values):
        raise ScenarioError(f"seeds = {seeds!r} is not allowed: a count >= 1 or distinct "
                            f"integers in [0, {SEED_LIMIT})")
    return values


def _names(controllers: str | Sequence[ControllerLike] | None) -> list[str]:
    """The controllers' names: a class is registered here; names are checked with the
    list (one line naming it); ``"open,etc"`` as the CLI writes it."""
    if controllers is None:
        return list(default_controllers())
    if isinstance(controllers, str):
        controllers = [c.strip() for c in controllers.split(",") if c.strip()]
    return [c if isinstance(c, str) else controller_name(c, "sumo") for c in controllers]


def _file_of(scenario: str | Path | Scenario | None) -> Path:
    if isinstance(scenario, Scenario):
        path = Path(scenario.source)
        if not path.is_file() or load_scenario(path) != scenario:
            raise ScenarioError(f"scenario = {scenario.name!r} is not allowed here: the "
                                "runs of an evaluation read their scenario from a file; "
                                "save it as TOML and pass the path")
        return path
    return scenario_file(scenario)


def evaluate(scenario: str | Path | Scenario | None = None, *,
             controllers: Sequence[ControllerLike] | None = None,
             seeds: int | Sequence[int] = 20, out: str | Path | None = None,
             horizon_s: float | None = None, warmup_s: float | None = None,
             allow_short_warmup: bool = False, workers: int | None = None,
             scheduler: str | None = None, share_warmup: bool = True,
             overwrite: bool = False, progress: bool = False, plots: bool = True,
             baseline_from: str | Path | None = None,
             runs_from: Sequence[str | Path] = (), command: str = "",
             option_names: Mapping[str, str] = API_NAMES) -> EvaluationResult:
    """Run every controller on the same SUMO seeds and compare each with the open loop,
    seed by seed (a paired comparison, every vehicle of the demand charged).

    Parameters
    ----------
    scenario : str, Path or Scenario, optional
        A scenario file or shipped name (a :class:`Scenario` read from a file unchanged).
    controllers : sequence of str or Controller subclass, optional
        Default :func:`default_controllers`; the open loop (the baseline) is added first.
        Your own must reach the worker processes: an entry point (``docs/api.md``).
    seeds : int or sequence of int
        A count N (seeds 1..N) or the seeds; a headline claim needs 20.
    out : str or Path, optional
        Default ``results/evaluate/<scenario file name>``; resumable.
    horizon_s, warmup_s : float, optional
        Control window and warm-up, s (default the scenario's).
    allow_short_warmup : bool
        Allow control to start inside the scenario's fill phase.
    workers, scheduler : optional
        Local processes (default one per core), or a Dask scheduler's address instead.
    share_warmup, overwrite, progress, plots : bool
        One warm-up per seed continued by every controller; discard a previous evaluation
        in ``out``; a progress bar; the report's figure.
    baseline_from, runs_from, command : optional
        An earlier evaluation whose open-loop runs to take; earlier evaluations or sweeps
        whose runs of a controller on all the seeds are the same SUMO runs (taken, not
        run); the command line printed at the top of the report.

    Returns
    -------
    EvaluationResult
        ``table``: per measure and controller the mean with its 95 % interval and the
        paired difference against the open loop (t interval, bootstrap, wins and
        losses); ``runs``: one row per finished run; ``files``: the report.

    Examples
    --------
    >>> ev = arzsumo.evaluate("default", controllers=["open", "etc"], seeds=10,
    ...                       out="results/evaluate-etc")        # doctest: +SKIP
    """
    path = _file_of(scenario)
    names = _names(controllers)
    check_warmup(load_scenario(path), warmup_s, horizon_s, allow_short_warmup, option_names)
    target = Path(out) if out is not None else Path("results") / "evaluate" / path.stem
    return run_evaluation(path, names, seed_list(seeds), out=target, horizon=horizon_s,
                          warmup=warmup_s, workers=workers, scheduler=scheduler,
                          share_warmup=share_warmup, overwrite=overwrite, progress=progress,
                          plots=plots, command=command,
                          baseline_from=Path(baseline_from) if baseline_from else None,
                          runs_from=[Path(d) for d in runs_from])


__all__ = ["default_controllers", "evaluate", "seed_list"]
