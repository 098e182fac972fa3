"""One run: the closed loop in SUMO (:func:`run`, checked first by :func:`prepare`, the
dry run) and the nonlinear PDE twin (:func:`twin`). ``arzsumo run`` and ``arzsumo twin``
call these; every check they make is made here."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from arzsumo.api.controllers import ControllerLike, controller_name
from arzsumo.api.results import RunResult, TwinResult
from arzsumo.api.scenarios import load_scenario
from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.road import with_network
from arzsumo.bridge.session import API_NAMES, SumoSession, prepare_run, run_prepared
from arzsumo.control.registry import controller_names
from arzsumo.engines.twin import run_twin
from arzsumo.io import dump_toml
from arzsumo.progress import RunProgress
from arzsumo.scenario import Scenario
from arzsumo.sumo.frontend import Frontend


def prepare(scenario: str | Path | Scenario | None = None, *,
            controller: ControllerLike | None = None, seed: int | None = None,
            horizon_s: float | None = None, warmup_s: float | None = None,
            fcd: bool | None = None, allow_short_warmup: bool = False,
            names: Mapping[str, str] = API_NAMES) -> PreparedRun:
    """Check a SUMO run as :func:`run` would, without starting SUMO (the dry run).

    Parameters are those of :func:`run` (``names``: how a refusal names them, the Python
    arguments by default; the CLI passes its options). Returns the checked run; its
    ``describe()`` is what ``arzsumo run --dry-run`` prints.

    Examples
    --------
    >>> import arzsumo
    >>> print(arzsumo.prepare("default", controller="etc", seed=1).describe())
    ... # doctest: +ELLIPSIS
    scenario default (...default.toml): valid
    ...
    """
    sc = load_scenario(scenario)
    return prepare_run(sc, controller=controller_name(controller, "sumo"), seed=seed,
                       horizon=horizon_s, warmup=warmup_s, fcd=fcd,
                       allow_short_warmup=allow_short_warmup, names=names)


def run(scenario: str | Path | Scenario | None = None, *,
        controller: ControllerLike | None = None, seed: int | None = None,
        horizon_s: float | None = None, warmup_s: float | None = None,
        fcd: bool | None = None, allow_short_warmup: bool = False,
        progress: bool | RunProgress = False, frontend: str = "libsumo") -> RunResult:
    """Run a scenario's closed loop in SUMO, with the PDE twins alongside.

    SUMO warms up under the meter's nominal plan, then the controller drives the ramp
    meter once per control period (sense, estimate, decide, actuate, record), then the
    demand drains; ``arzsumo run`` does the same.

    Parameters
    ----------
    scenario : str, Path or Scenario, optional
        A scenario file, a shipped name (``"default"``, ``"stop_and_go_idm"``) or a loaded
        :class:`Scenario`; the shipped default when None.
    controller : str or Controller subclass, optional
        A registered name (``"open"``, ``"backstepping"``, ``"etc"``, ``"observer-etc"``,
        ``"alinea"``, ...) or your own :class:`arzsumo.Controller` subclass; default the
        scenario's ``[run] controller``.
    seed : int, optional
        SUMO's seed, in [0, 2^31); default ``[sumo] seed``. The same scenario and seed
        give the same numbers.
    horizon_s : float, optional
        Control window after the warm-up, s (at least one control period); default
        ``[sumo] horizon_s``.
    warmup_s : float, optional
        Warm-up under the nominal plan, s; default ``[run] warmup_s``. Shorter than the
        scenario's fill phase only with ``allow_short_warmup``.
    fcd : bool, optional
        Keep SUMO's trajectories of every vehicle (``fcd.xml.gz`` when saved).
    allow_short_warmup : bool
        Allow control to start inside the fill phase.
    progress : bool
        A progress bar on stderr.
    frontend : str
        ``"libsumo"`` (default), ``"traci"``, or ``"gui"`` (sumo-gui; needs a display).

    Returns
    -------
    RunResult
        Summary, per-period and per-cell frames (SI), the resolved scenario; ``save(DIR)``
        writes what ``arzsumo run --out DIR`` writes.

    Raises
    ------
    arzsumo.errors.ArzsumoError
        Before SUMO starts, one line naming the key or argument and what is allowed.

    Examples
    --------
    >>> import arzsumo
    >>> res = arzsumo.run("default", controller="open", seed=3, warmup_s=600,
    ...                   horizon_s=30)                       # doctest: +SKIP
    >>> res.summary.counts.plan_changes              # doctest: +SKIP
    0
    """
    prepared = prepare(scenario, controller=controller, seed=seed, horizon_s=horizon_s,
                       warmup_s=warmup_s, fcd=fcd, allow_short_warmup=allow_short_warmup)
    return run_checked(prepared, progress=progress, frontend=frontend)


def run_checked(prepared: PreparedRun, *, progress: bool | RunProgress = False,
                frontend: str = "libsumo") -> RunResult:
    """Run what :func:`prepare` checked (the CLI claims its output directory in between)."""
    Frontend(frontend).check()     # no display or no sumo-gui: one line, before SUMO
    session = run_prepared(prepared, progress=progress, frontend=frontend)
    return RunResult.of(session.result, scenario_text(prepared.scenario, session))


def scenario_text(sc: Scenario, session: SumoSession | None = None) -> str:
    """``scenario.toml`` of a run: the scenario's file as written (its tables as TOML when
    it was not read from a file), then the resolved settings as comments."""
    source = Path(sc.source)
    as_written = source.is_file() and load_scenario(source) == sc   # not changed by with_
    text = source.read_text(encoding="utf-8") if as_written else dump_toml(
        {"name": sc.name, "description": sc.description, **sc.tables})
    return text + (session.resolved_comment() if session is not None else "")


def twin_controller(sc: Scenario, controller: ControllerLike | None) -> tuple[Scenario, str]:
    """(scenario whose ``[twin] controller`` is the one to run, where it came from).

    ``controller`` wins; then a ``[twin] controller`` written in the file; then the
    ``[run] controller`` written there, when it runs in the twin; else the ``[twin]``
    default (the open loop).
    """
    run_name = sc.written("run", "controller")
    if controller is not None:
        name, origin = controller_name(controller, "twin"), "--controller"
    elif sc.written("twin", "controller") is not None:
        return sc, "[twin] controller"
    elif run_name is not None and run_name in controller_names("twin"):
        name, origin = run_name, "[run] controller"
    else:
        why = f"; [run] controller = {run_name} does not run in the twin" if run_name else ""
        return sc, f"the default{why}"
    return sc.with_({"twin.controller": name}), origin


def twin(scenario: str | Path | Scenario | None = None, *,
         controller: ControllerLike | None = None, baseline: bool = True) -> TwinResult:
    """Run the nonlinear mixed-autonomy ARZ model (the PDE twin) on a scenario.

    Parameters
    ----------
    scenario : str, Path or Scenario, optional
        As in :func:`run`; its ``[initial]`` condition starts the twin.
    controller : str or Controller subclass, optional
        Default: ``[twin] controller``, else ``[run] controller`` when it runs in the twin,
        else the open loop.
    baseline : bool
        Also run the open loop, for the changes relative to it in the summary.

    Returns
    -------
    TwinResult
        Summary, fields and control frames (SI); ``save(DIR)`` writes what ``arzsumo twin
        --out DIR`` writes. ``complete`` is False when the state left the physical domain.

    Examples
    --------
    >>> import arzsumo
    >>> res = arzsumo.twin("paper/base_etc", controller="etc")
    >>> res.summary.controller, res.summary.triggers < 450
    ('etc', True)
    """
    # a [network]: the twin runs on the section's length and width read from it
    sc, _ = twin_controller(with_network(load_scenario(scenario)), controller)
    return TwinResult.of(run_twin(sc, baseline=baseline))


__all__ = ["prepare", "run", "run_checked", "scenario_text", "twin", "twin_controller"]
