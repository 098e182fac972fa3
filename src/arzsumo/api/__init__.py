"""The public API, re-exported by :mod:`arzsumo` (``arzsumo.run``, ``arzsumo.twin``, ...).

Each module keeps its ``__all__``; this package gathers them under the names of
:data:`arzsumo._API`, imported on first use like the root's: ``import arzsumo.api.scenarios``
(what the CLI needs to read a scenario) loads neither SUMO nor pandas. The CLI calls these
functions: every check a command makes is made here, so a Python caller gets it too.
"""

from __future__ import annotations

from typing import Any

import arzsumo

__all__ = sorted(arzsumo._API)


def __getattr__(name: str) -> Any:
    if name in arzsumo._API:
        return getattr(arzsumo, name)
    raise AttributeError(f"module 'arzsumo.api' has no attribute {name!r}")
