"""The premise's speed fields and the pulse gate's floors.

A premise row holds per class its speed field (periods x cells, m/s); the floors are the
level the paired deviation D keeps without a pulse's effect (m/s m^(1/2)): the distance
of two seeds' baselines, or the late part of a seed's own pulse
(:func:`floors`, research/premise.md).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from arzsumo_studies.gates import deviation_norm
from arzsumo_studies.premise.runs import CLASSES

#: the floor methods of the pulse gate
FLOORS = ("auto", "seeds", "late", "none")
#: the late part of a record the "late" floor is read from (its last quarter)
LATE_SHARE = 0.25


def _array(values: Any) -> np.ndarray:
    return np.array(values, dtype=float)


def classes_of(base: Mapping[str, Any]) -> list[str]:
    """The classes a baseline row sampled (at least two lateral samples)."""
    return [c for c in CLASSES if base["class_samples"][c] >= 2]


def class_fields(row: Mapping[str, Any], classes: Sequence[str]) -> dict[str, np.ndarray]:
    """The speed fields (periods x cells, m/s) of ``classes`` in a row."""
    return {c: _array(row[f"v_{c}"]) for c in classes}


def deviation_norms(a: Mapping[str, np.ndarray], b: Mapping[str, np.ndarray],
           dx: float) -> dict[str, np.ndarray]:
    """D(t) per class and their ``total`` (m/s m^(1/2))."""
    d = {c: deviation_norm(a[c], b[c], dx) for c in a}
    d["total"] = np.sqrt(sum(v ** 2 for v in d.values()))
    return d


def _median(v: np.ndarray) -> float:
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else 0.0


def floors(rows: Mapping[int, Mapping[str, Mapping[str, Any]]], method: str,
           held: Sequence[int] | None = None) -> tuple[str, dict[int, dict[str, float]]]:
    """The pulse gate's floor per seed, class and ``total`` (m/s m^(1/2)).

    ``seeds``: the median D between the seed's baseline and the next seed's (cyclic): two
    runs that differ only by chance; with ``held`` (two or more of the seeds), the cycle
    runs over the held seeds only and every other seed gets their floors' median (a
    deadlocked baseline is not a run that differs by chance). ``late``: the median D of
    the seed's own pulse against its baseline over the record's last quarter (it counts
    a deviation that persists as noise: a stream that keeps the pulse looks stable).
    ``none``: 0. ``auto``: ``seeds`` with two seeds or more, else ``late``. Returns
    (method, floors).
    """
    seeds = sorted(rows)
    if method == "auto":
        method = "seeds" if len(seeds) >= 2 else "late"
    if method == "none":
        return method, {s: {} for s in seeds}
    if method == "late":
        return method, {s: _late_floor(rows[s]) for s in seeds}
    cycle = sorted(held) if held is not None and len(held) >= 2 else seeds
    out = {s: _pair_floor(rows[s], rows[cycle[(i + 1) % len(cycle)]])
           for i, s in enumerate(cycle)}
    keys = set().union(*out.values())
    typical = {k: float(np.median([f[k] for f in out.values() if k in f])) for k in keys}
    return method, {s: out.get(s, typical) for s in seeds}


def _pair_floor(a: Mapping[str, Mapping[str, Any]], b: Mapping[str, Mapping[str, Any]]
                ) -> dict[str, float]:
    """Median D between two seeds' baselines, per class and total."""
    base, other = a["baseline"], b["baseline"]
    cls = classes_of(base)
    d = deviation_norms(class_fields(base, cls), class_fields(other, cls),
                        float(base["dx_m"]))
    return {k: _median(v) for k, v in d.items()}


def _late_floor(runs: Mapping[str, Mapping[str, Any]]) -> dict[str, float]:
    """Median D of a seed's pulse against its baseline over the record's last quarter."""
    base = runs["baseline"]
    cls = classes_of(base)
    d = deviation_norms(class_fields(base, cls), class_fields(runs["pulse"], cls),
                        float(base["dx_m"]))
    start = int(len(d["total"]) * (1 - LATE_SHARE))
    return {k: _median(v[start:]) for k, v in d.items()}
