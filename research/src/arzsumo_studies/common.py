"""What the studies of :mod:`arzsumo_studies.cli.catalog` share: their command-line options,
their error type, and the base scenarios they start from.

Every study takes ``--out DIR`` (default ``results/studies/<name>``: tables, figures and
the runs it made, continued by a later call with the same directory) and ``--docs
[DIR]`` (also publish: regenerate the study's block of its results page ``DIR/<page>.md``,
its tables and figures in ``DIR/<page>/``; ``DIR`` defaults to ``research/results`` under the
working directory; each study module names its ``PAGE``). Studies
that run simulations take ``--seeds`` (``1-10`` or ``1,2,3``), ``--workers`` (local
processes, default one per core), ``--scheduler`` (a Dask cluster instead), ``--quiet``
(no progress bar) and ``--list`` (print the runs of the design and exit); studies that
draw take ``--no-plots``.
"""

from __future__ import annotations

import argparse
import copy
import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from arzsumo.argtypes import (  # noqa: F401 (the studies' option types, re-exported)
    SEED_LIMIT,
    fraction,
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
    seed_list,
)
from arzsumo.errors import (
    EXIT_SOME_FAILED,  # noqa: F401 (re-exported)
    ArzsumoError,
)
from arzsumo.io import read_toml
from arzsumo.resources import default_scenario, shipped_scenarios_dir
from arzsumo.sweep.spec import SweepSpec, sweep_from_dict

#: where a study's results go by default (``--out``), relative to the working directory
RESULTS_DIR = Path("results") / "studies"
#: where ``--docs`` publishes a study's page by default, relative to the working directory
DOCS_DIR = Path("research") / "results"
#: the fields every study's frozen options share, and what they mean
SHARED_FIELDS = {
    "out": "the study's directory (Path; resumable: a later call runs only what is "
           "missing)",
    "docs": "also regenerate the study's block of research/results/PAGE.md (Path, or None: "
            "no page)",
    "workers": "local processes (int, or None: one per core); ignored with scheduler",
    "scheduler": "a Dask scheduler's address to run on instead (str, or None: local)",
    "progress": "draw a progress bar (bool)",
}
#: the ``[sumo]`` keys of the meter realisation (one vehicle per green, with a yellow) that
#: the shipped default carries; the meter studies and the ablation start from the plain
#: fixed cycle without them
METER_KEYS = ("meter_mode", "meter_clearance_s")


class StudyError(ArzsumoError, ValueError):
    """A study that cannot run as asked: a missing input, an invalid option value."""


def names_among(text: str, allowed: Sequence[str], flag: str) -> list[str]:
    """The comma-separated names of ``text``, each among ``allowed``, in ``allowed``'s
    order without repeats; else a StudyError naming ``flag`` and the value as written."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names or any(n not in allowed for n in names):
        raise StudyError(f"{flag} = {text!r} is not allowed: a comma-separated list of "
                         f"{', '.join(allowed)}")
    return sorted(set(names), key=list(allowed).index)


# -- base scenarios ------------------------------------------------------------------------
#: the scenario file the studies' results pages were measured on, and their default: the
#: former default, whose vehicles ride in three lateral files (research/results/)
FORMER_DEFAULT = "lateral_files.toml"


def shipped_scenario(name: str) -> Path:
    """The shipped scenario file ``name`` (``default.toml``, ``legacy_default.toml``)."""
    return default_scenario() if name == default_scenario().name else \
        shipped_scenarios_dir() / name


def scenario_data(path: Path) -> dict[str, Any]:
    """The tables of the scenario file ``path`` as a mapping (a copy)."""
    _, data = read_toml(path, "scenario", StudyError)
    return copy.deepcopy(data)


def fixed_cycle(data: dict[str, Any]) -> dict[str, Any]:
    """``data`` with the meter realisation keys (:data:`METER_KEYS`) removed: the plain
    fixed-cycle meter the meter studies and the ablation start from."""
    out = copy.deepcopy(data)
    for key in METER_KEYS:
        out.get("sumo", {}).pop(key, None)
    return out


def file_stem(name: object) -> str:
    """``name`` (a scenario's, as the user wrote it) made safe as part of a file name:
    characters other than letters, digits, ``-``, ``_`` and ``.`` become ``_``, so that a
    name can never lead outside the directory it is written in."""
    import re

    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", str(name)).lstrip(".")
    return stem or "scenario"


def seed_text(seeds: list[int]) -> str:
    """``1-10`` for a run of consecutive seeds, else ``1,3,7``."""
    seeds = sorted(seeds)
    if len(seeds) > 2 and seeds == list(range(seeds[0], seeds[-1] + 1)):
        return f"{seeds[0]}-{seeds[-1]}"
    return ",".join(map(str, seeds))


def study_spec(name: str, base: Path, data: dict[str, Any] | None = None, **keys: Any
               ) -> SweepSpec:
    """A sweep built in code for study ``name`` (``keys``: the sweep file's keys, e.g.
    ``seeds``, ``set``, ``axis``) on the scenario file ``base``, whose tables are
    replaced by ``data`` when given (a base changed in code, e.g. :func:`fixed_cycle`)."""
    base = Path(base).resolve()
    spec = sweep_from_dict({"name": name, "base": str(base), "engine": "sumo", **keys},
                           f"study {name}", root=base.parent)
    return spec if data is None else replace(spec, base_data=data)


def print_list(run_ids: list[str],
               read_instead: tuple[str, Path | Sequence[Path]] | None = None) -> int:
    """``--list``: one run ID per line; exit code 0. ``read_instead``: the option and the
    file(s) a study reads instead of running (``--series``, ``--from``): then no runs,
    and one line that says so."""
    if read_instead is not None:
        flag, paths = read_instead
        named = paths if isinstance(paths, Path) else " ".join(map(str, paths))
        print(f"no runs: {flag} {named} is read instead")
        return 0
    for run_id in run_ids:
        print(run_id)
    return 0


def number_list(text: str) -> list[float]:
    """Comma-separated finite numbers: ``0.2,0.5,0.8``."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: comma-separated numbers")
    return values


def fraction_list(text: str) -> list[float]:
    """Comma-separated numbers in [0, 1] (shares): ``0.2,0.5,0.8``."""
    try:
        values = number_list(text)
    except argparse.ArgumentTypeError:
        values = []
    if not values or not all(0.0 <= v <= 1.0 for v in values):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: comma-separated numbers "
                                         "in [0, 1]")
    return values
