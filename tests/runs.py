"""Runs for tests, made as users' runs are: a scenario, its keys changed, ``prepare_run``.

A test that needs a variant of a shipped scenario writes the keys it changes
(``{"run.kernel_cells": 50}``, as a scenario file would) and the options ``arzsumo run``
takes (controller, seed, horizon, warm-up); :func:`prepared` does exactly that and
nothing else, so a test's run is one a user could start from a file.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.session import prepare_run
from arzsumo.scenario import Scenario, load_scenario

ROOT = Path(__file__).resolve().parents[1]
LEGACY = ROOT / "scenarios" / "legacy_default.toml"

#: small kernel and twin grids: short tests, the closed loop unchanged in kind
SMALL_GRIDS = {"run.kernel_cells": 50, "run.twin_cells": 50}


def prepared(scenario: Scenario | Path, changes: Mapping[str, Any] | None = None,
             **options: Any) -> PreparedRun:
    """``prepare_run`` of ``scenario`` (loaded if a path) with ``changes`` (``"table.key"``
    to a value in the file's units) applied first; ``options`` are ``prepare_run``'s
    (``controller``, ``seed``, ``horizon`` s, ``warmup`` s, ``fcd``)."""
    sc = load_scenario(scenario) if isinstance(scenario, Path) else scenario
    return prepare_run(sc.with_(changes) if changes else sc, **options)
