"""Files shipped inside the package: scenario files, sweep files and the SUMO network.

They live in ``arzsumo/data/`` and are found through :mod:`importlib.resources`, so an
installed package runs from any working directory (docs/install.md, docs/layout.md).
"""

from __future__ import annotations

import re
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


#: directories (under the shipped scenarios) of the files a scenario argument may name
SCENARIO_DIRS = (".", "paper")
#: directory of the files a sweep argument may name
SWEEP_DIRS = ("sweeps",)
_NAME = re.compile(r"^(?:([A-Za-z0-9_-]+)/)?([A-Za-z0-9_.-]+?)(?:\.toml)?$")


def shipped_names(dirs: tuple[str, ...] = SCENARIO_DIRS) -> list[str]:
    """Names of the shipped files in ``dirs``, in order: the file stems (``default``,
    ``base_etc``), which :func:`shipped_named` resolves."""
    root = shipped_scenarios_dir()
    return [f.stem for d in dirs for f in sorted((root / d).glob("*.toml"))]


def shipped_named(name: str, dirs: tuple[str, ...] = SCENARIO_DIRS) -> Path | None:
    """The shipped file called ``name`` in ``dirs``, or None.

    ``name`` is a file stem (``default``, ``base_etc``), with ``.toml`` or not, or
    ``DIR/STEM`` (``paper/base_etc``) with DIR one of ``dirs``; the first of ``dirs``
    holding it wins (the stems are unique across the shipped files).
    """
    m = _NAME.match(name)
    if m is None:
        return None
    sub, stem = m.groups()
    if sub is not None and (sub not in dirs or sub == "."):
        return None
    root = shipped_scenarios_dir()
    for d in (sub,) if sub else dirs:
        path = root / d / f"{stem}.toml"
        if path.is_file():
            return path
    return None
