"""Files shipped inside the package: scenario files, sweep files and the SUMO network.

They live in ``arzsumo/data/`` and are found through :mod:`importlib.resources`, so an
installed package (``pip install .``, not editable) runs from any working directory. A
source checkout keeps the paths users know: ``scenarios/`` and ``sumo_nets/`` at the
repository root are symbolic links to these directories.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

from arzsumo.errors import ArzsumoError

#: The scenario of ``arzsumo run`` without a scenario argument (and ``make run``).
DEFAULT_SCENARIO_NAME = "default.toml"


def _data_dir(name: str) -> Path:
    """The shipped directory ``arzsumo/data/<name>`` as a path on disk."""
    res = files("arzsumo") / "data" / name
    # SUMO and the TOML readers need real files: a zipped install has none.
    if not isinstance(res, Path) or not res.is_dir():
        raise ArzsumoError(f"the package's data directory {name!r} is not on disk ({res}); "
                           "allowed: an installation unpacked on disk (pip install .)")
    return res


def shipped_scenarios_dir() -> Path:
    """Directory of the shipped scenario files (``paper/`` and ``sweeps/`` inside it)."""
    return _data_dir("scenarios")


def shipped_sweeps_dir() -> Path:
    """Directory of the shipped sweep files."""
    return shipped_scenarios_dir() / "sweeps"


def shipped_nets_dir() -> Path:
    """Directory of the shipped SUMO network (``ramp.net.xml``, routes, ``ramp.sumocfg``)."""
    return _data_dir("sumo_nets")


def default_scenario() -> Path:
    """The shipped default scenario file of ``arzsumo run``."""
    return shipped_scenarios_dir() / DEFAULT_SCENARIO_NAME
