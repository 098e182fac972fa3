"""Scenarios by name or path: what every entry point (Python, the CLI, the environments)
loads a scenario through.

``load_scenario("default")`` and ``load_scenario("scenarios/default.toml")`` read the
same file: an argument that is not an existing file is looked up among the shipped files
(:func:`arzsumo.resources.shipped_named`; ``arzsumo list`` shows the names).
"""

from __future__ import annotations

from pathlib import Path

from arzsumo.errors import ScenarioError
from arzsumo.resources import (
    SCENARIO_DIRS,
    SWEEP_DIRS,
    default_scenario,
    shipped_named,
    shipped_names,
)
from arzsumo.scenario import Scenario
from arzsumo.scenario import load_scenario as _load_file
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


def scenario_file(name_or_path: str | Path | None, default: Path | None = None) -> Path:
    """The scenario file named by ``name_or_path``: a path, else a shipped scenario name
    (``default``, ``paper/base_etc``); ``default`` when it is None (the shipped default
    scenario when that is None too). Raises :class:`~arzsumo.errors.ScenarioError`
    naming the argument and the shipped names when it is neither."""
    if name_or_path is None:
        return default if default is not None else default_scenario()
    return _resolved(str(name_or_path), SCENARIO_DIRS, "scenario")


def sweep_file(text: str) -> Path:
    """The sweep file named by ``text``: a path, else a shipped sweep name
    (``demand_sumo``)."""
    return _resolved(text, SWEEP_DIRS, "sweep")


def load_scenario(name_or_path: str | Path | Scenario | None = None) -> Scenario:
    """Read and validate a scenario.

    Parameters
    ----------
    name_or_path : str, pathlib.Path or Scenario, optional
        A TOML file, or the name of a shipped scenario (``"default"``,
        ``"stop_and_go_idm"``, ``"paper/base_etc"``; ``arzsumo list`` shows them). None
        reads the shipped default; a :class:`Scenario` is returned as it is.

    Returns
    -------
    Scenario
        The validated, frozen scenario (every table parsed into its section).

    Raises
    ------
    arzsumo.errors.ScenarioError
        One line naming the file, table, key and value, and what is allowed.

    Examples
    --------
    >>> import arzsumo
    >>> sc = arzsumo.load_scenario("default")
    >>> sc.name, sc.params.length
    ('default', 1000.0)
    """
    if isinstance(name_or_path, Scenario):
        return name_or_path
    return _load_file(scenario_file(name_or_path))


__all__ = ["load_scenario", "scenario_file", "sweep_file"]
