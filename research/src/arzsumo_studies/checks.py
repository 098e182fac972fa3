"""The checks of the studies' frozen options (``<Name>Options.__post_init__``).

Each refuses a value with a :class:`~arzsumo_studies.common.StudyError` whose message
names the field, the value and what is allowed (:func:`arzsumo.errors.require`), so a
study called from Python refuses what its command line's parser would.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path

from arzsumo.argtypes import SEED_LIMIT
from arzsumo.errors import require
from arzsumo_studies.common import StudyError


def seeds(value: Sequence[int], field: str = "seeds", empty: bool = False) -> None:
    """SUMO seeds: integers in [0, 2^31), none repeated, at least one (unless
    ``empty``)."""
    ok = (empty or len(value) > 0) and len(set(value)) == len(value) and all(
        isinstance(s, int) and 0 <= s < SEED_LIMIT for s in value)
    require(ok, field, value, "distinct integers in [0, 2^31)"
            + ("" if empty else ", at least one"), StudyError)


def positive(value: float | None, field: str, optional: bool = False) -> None:
    """A finite number > 0 (None too when ``optional``)."""
    if optional and value is None:
        return
    require(value is not None and math.isfinite(value) and value > 0, field, value,
            "a finite number > 0", StudyError)


def non_negative(value: float | None, field: str, optional: bool = False) -> None:
    """A finite number >= 0 (None too when ``optional``)."""
    if optional and value is None:
        return
    require(value is not None and math.isfinite(value) and value >= 0, field, value,
            "a finite number >= 0", StudyError)


def fraction(value: float, field: str) -> None:
    """A number in [0, 1] (a share)."""
    require(0.0 <= value <= 1.0, field, value, "a number in [0, 1]", StudyError)


def count(value: int | None, field: str, least: int = 1, optional: bool = False) -> None:
    """An integer >= ``least`` (None too when ``optional``: e.g. workers, one per core)."""
    if optional and value is None:
        return
    require(isinstance(value, int) and value >= least, field, value,
            f"an integer >= {least}", StudyError)


def among(value: object, allowed: Collection[object], field: str) -> None:
    """One of ``allowed``."""
    require(value in allowed, field, value,
            "one of " + ", ".join(map(str, allowed)), StudyError)


def all_among(values: Sequence[object], allowed: Collection[object], field: str) -> None:
    """At least one value, each one of ``allowed``."""
    require(len(values) > 0 and all(v in allowed for v in values), field, values,
            "at least one of " + ", ".join(map(str, allowed)), StudyError)


def numbers(values: Sequence[float], field: str) -> None:
    """At least one number, each finite."""
    require(len(values) > 0 and all(math.isfinite(v) for v in values), field, values,
            "at least one finite number", StudyError)


@dataclass(frozen=True)
class Shared:
    """The fields every study's options share (their meaning:
    :data:`~arzsumo_studies.common.SHARED_FIELDS`): ``docs``, ``workers``, ``scheduler``.
    A study's options subclass it and call ``super().__post_init__()``."""

    docs: Path | None = None
    workers: int | None = None
    scheduler: str | None = None

    def __post_init__(self) -> None:
        count(self.workers, "workers", optional=True)
