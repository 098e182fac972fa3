"""A cache of identification runs: one SUMO run's ReplayData, keyed by what made it.

A refit with other parameters, start values or numerics should not rerun SUMO (15 min on
the default scenario). The key is a hash of the run's scenario tables (what SUMO and the
measurement see), its seed and the package version; the value is an ``.npz`` of the
ReplayData arrays and a few numbers about the run. Files live under
``$ARZSUMO_CACHE/identify-runs`` (``~/.cache/arzsumo`` by default) and are written
atomically; a file that does not load is ignored and rewritten.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.identify import ReplayData
from arzsumo.io import atomic_file
from arzsumo.version import __version__

#: the fields of ReplayData kept in the cache
ARRAYS = ("t", "x", "fields", "initial", "inlet", "outflow", "scale")


def cache_dir() -> Path:
    """``$ARZSUMO_CACHE/identify-runs`` (default ``~/.cache/arzsumo/identify-runs``)."""
    root = os.environ.get("ARZSUMO_CACHE", Path.home() / ".cache" / "arzsumo")
    return Path(root) / "identify-runs"


def run_key(tables: dict[str, Any], seed: int) -> str:
    """Hash of the scenario tables a run used, its seed and the package version."""
    text = json.dumps({"tables": tables, "seed": seed, "version": __version__},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def load_run(key: str, name: str) -> tuple[ReplayData, dict[str, float]] | None:
    """The cached data of ``key`` (relabelled ``name``) and its numbers, or None."""
    path = cache_dir() / f"{key}.npz"
    try:
        with np.load(path) as z:
            arrays = {k: z[k] for k in ARRAYS}
            info = json.loads(str(z["info"]))
        return ReplayData(**arrays, name=name), info
    except (OSError, KeyError, ValueError):
        return None


def save_run(key: str, data: ReplayData, info: dict[str, float]) -> None:
    """Store ``data`` and ``info`` under ``key`` (atomically)."""
    path = cache_dir() / f"{key}.npz"
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_file(path) as tmp, open(tmp, "wb") as f:
        np.savez(f, **{k: getattr(data, k) for k in ARRAYS}, info=json.dumps(info))
