"""Scenario and sweep arguments of the CLI: a file or a shipped name, and the checks a
command makes on the scenario before any simulation.

``arzsumo run default`` and ``arzsumo run scenarios/default.toml`` run the same file:
an argument that is not an existing file is looked up among the shipped files
(:func:`arzsumo.resources.shipped_named`; ``arzsumo list`` shows the names).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.errors import ScenarioError
from arzsumo.resources import (
    SCENARIO_DIRS,
    SWEEP_DIRS,
    default_scenario,
    shipped_named,
    shipped_names,
)
from arzsumo.scenario import Scenario, load_scenario, scenario_from_preset
from arzsumo.tables import did_you_mean


def _resolved(text: str, dirs: tuple[str, ...], field: str) -> Path:
    path = Path(text)
    if path.is_file():
        return path
    named = shipped_named(text, dirs)
    if named is not None:
        return named
    if path.exists():            # a directory: the reader names it
        return path
    names = sorted(shipped_names(dirs[:1]), key=lambda n: (n != "default", n))
    more = " or a paper experiment" if len(dirs) > 1 else ""
    raise ScenarioError(f"{field} = {text!r}{did_you_mean(text, shipped_names(dirs))} does "
                        "not exist: neither a file nor a shipped name; allowed: a TOML file "
                        f"or one of {', '.join(names)}{more} ('arzsumo list')")


def scenario_file(text: str | None, default: Path | None = None) -> Path:
    """The scenario file named by ``text``: a path, else a shipped scenario name
    (``default``, ``paper/base_etc``); ``default`` when ``text`` is None (the shipped
    default scenario when that is None too). Raises :class:`ScenarioError` naming the
    argument and the shipped names when it is neither."""
    if text is None:
        return default if default is not None else default_scenario()
    return _resolved(text, SCENARIO_DIRS, "scenario")


def sweep_file(text: str) -> Path:
    """The sweep file named by ``text``: a path, else a shipped sweep name
    (``demand_sumo``)."""
    return _resolved(text, SWEEP_DIRS, "sweep")


def load_named(text: str | None, default: Path | None = None) -> tuple[Path, Scenario]:
    """(file, validated scenario) of a scenario argument (:func:`scenario_file`)."""
    path = scenario_file(text, default)
    return path, load_scenario(path)


def scenario_of(args: argparse.Namespace) -> Scenario:
    """The scenario of ``--scenario FILE|NAME``, else of the ``--preset``."""
    if getattr(args, "scenario", None):
        return load_named(args.scenario)[1]
    return scenario_from_preset(args.preset)


def check_warmup(sc: Scenario, warmup: float | None, horizon: float | None,
                 allow_short: bool) -> None:
    """Refuse control that starts inside the scenario's fill phase.

    A scenario with ``[sumo] fill_s`` > 0 sends a fill demand from t = 0 until the queue
    of the merge has filled the section; control is meant to start after it. With a
    warm-up (``warmup``, s, else ``[run] warmup_s``) shorter than the fill, the control
    window (``horizon``, s, else ``[sumo] horizon_s``) measures the fill, not the
    controller: refused in one line naming the values, unless ``allow_short``.
    """
    fill = sc.sumo.fill_duration
    warm = sc.run.warmup if warmup is None else float(warmup)
    if allow_short or fill <= 0 or warm >= fill:
        return
    window = sc.sumo.horizon if horizon is None else float(horizon)
    given = (f"--warmup = {warm:g}" if warmup is not None else
             f"{sc.source}: [run] warmup_s = {sc.written('run', 'warmup_s', warm)}")
    raise ScenarioError(f"{given} is not allowed: the control window ({warm:g}-"
                        f"{warm + window:g} s) starts inside the fill phase of {sc.name} "
                        f"([sumo] fill_s = {fill:g} s), so its measures describe the fill; "
                        f"allowed: a warm-up >= {fill:g} s, or --allow-short-warmup")
