"""On-disk cache of backstepping kernels, keyed by a hash of the system and the grid.

A repeated run skips the kernel solve. Each entry stores its key and a checksum of its
arrays; an entry that does not load, does not match its key, fails its checksum or holds
non-finite values is recomputed and rewritten, never trusted. The cache directory is
``$ARZSUMO_CACHE`` if set, else ``~/.cache/arzsumo``. It reads and writes files, so it is
a room of its own above ``control`` (docs/layout.md).
"""

from __future__ import annotations

import hashlib
import logging
import os
import zipfile
from pathlib import Path

import numpy as np

from arzsumo.control.kernels import Kernels, solve_kernels
from arzsumo.io import atomic_file
from arzsumo.model.characteristic import CharacteristicSystem

log = logging.getLogger(__name__)

#: bump when the kernel solver's numerics change, so old entries are not reused
SOLVER_VERSION = "mocheun-cubic-1"
_FIELDS = ("x", "K", "M", "L", "N")


def cache_dir() -> Path:
    """The kernel cache directory."""
    return Path(os.environ.get("ARZSUMO_CACHE", Path.home() / ".cache" / "arzsumo")) / "kernels"


def kernel_key(system: CharacteristicSystem, n_cells: int) -> str:
    """SHA-256 of the system's coefficients, the grid size and the solver version."""
    h = hashlib.sha256(SOLVER_VERSION.encode())
    for arr in (system.lam, system.j_hat, system.Q, system.R):
        h.update(np.ascontiguousarray(arr, dtype="<f8").tobytes())
    h.update(np.array([system.length, n_cells], dtype="<f8").tobytes())
    return h.hexdigest()


def _checksum(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in _FIELDS:
        h.update(np.ascontiguousarray(arrays[name], dtype="<f8").tobytes())
    return h.hexdigest()


def _load(path: Path, key: str, n_cells: int) -> Kernels | None:
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: data[name] for name in _FIELDS}
            stored_key, stored_sum = str(data["key"]), str(data["checksum"])
    except (OSError, KeyError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        log.warning("kernel cache entry %s is unreadable (%s); recomputing", path.name, exc)
        return None
    ok = (stored_key == key and stored_sum == _checksum(arrays)
          and arrays["x"].shape == (n_cells + 1,)
          and all(np.isfinite(a).all() for a in arrays.values()))
    if not ok:
        log.warning("kernel cache entry %s is stale or corrupt; recomputing", path.name)
        return None
    return Kernels(**arrays)


def cached_kernels(system: CharacteristicSystem, n_cells: int,
                   directory: str | Path | None = None) -> Kernels:
    """Kernels for ``system`` on ``n_cells`` cells, from the cache or solved and stored."""
    key = kernel_key(system, n_cells)
    path = Path(directory) / "kernels" if directory else cache_dir()
    entry = path / f"{key}.npz"
    if entry.exists():
        kernels = _load(entry, key, n_cells)
        if kernels is not None:
            log.debug("kernels loaded from %s", entry)
            return kernels
    kernels = solve_kernels(system, n_cells)
    arrays = {name: getattr(kernels, name) for name in _FIELDS}
    try:
        with atomic_file(entry) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, key=np.array(key), checksum=np.array(_checksum(arrays)), **arrays)
    except OSError as exc:                 # a read-only cache must not stop a run
        log.warning("could not write kernel cache %s: %s", entry, exc)
    return kernels
