"""The ``type=`` checks of every command-line option: the CLI's and the studies'.

Each reads the text as a number (or a list) and refuses what the option does not allow
with ``argparse.ArgumentTypeError("TEXT is not allowed: ALLOWED")``; the CLI's parser
prints that as one line and exits with code 2 (:mod:`arzsumo.cli.args`).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import Any

#: SUMO's seed range
SEED_LIMIT = 2**31


def checked(name: str, kind: type, ok: Callable[[Any], bool], allowed: str,
            doc: str) -> Callable[[str], Any]:
    """An argparse ``type=``: ``text`` read as ``kind`` and kept when ``ok``; otherwise
    refused as "TEXT is not allowed: ALLOWED"."""
    def parse(text: str) -> Any:
        try:
            value = kind(text)
        except ValueError:
            what = "an integer" if kind is int else "a number"
            raise argparse.ArgumentTypeError(f"{text} is not allowed: {what}") from None
        if not ok(value):
            raise argparse.ArgumentTypeError(f"{text} is not allowed: {allowed}")
        return value

    parse.__name__ = parse.__qualname__ = name
    parse.__doc__ = doc
    return parse


positive_float = checked("positive_float", float, lambda v: math.isfinite(v) and v > 0,
                         "a finite number > 0",
                         "A finite number > 0 (times, periods, design constants).")
non_negative_float = checked("non_negative_float", float,
                             lambda v: math.isfinite(v) and v >= 0, "a finite number >= 0",
                             "A finite number >= 0 (lengths that may be absent).")
negative_float = checked("negative_float", float, lambda v: math.isfinite(v) and v < 0,
                         "a finite number < 0",
                         "A finite number < 0 (speeds of waves that travel upstream).")
fraction = checked("fraction", float, lambda v: 0.0 <= v <= 1.0, "a number in [0, 1]",
                   "A number in [0, 1] (shares).")
positive_int = checked("positive_int", int, lambda v: v >= 1, "an integer >= 1",
                       "An integer >= 1 (workers, jobs).")
non_negative_int = checked("non_negative_int", int, lambda v: v >= 0, "an integer >= 0",
                           "An integer >= 0 (counts that may be zero).")
seed_int = checked("seed_int", int, lambda v: 0 <= v < SEED_LIMIT, "an integer in [0, 2^31)",
                   "A random seed: an integer in [0, 2^31) (SUMO's range).")
cells_int = checked("cells_int", int, lambda v: v >= 4, "an integer >= 4",
                    "A grid size: an integer >= 4.")


def seed_list(text: str) -> list[int]:
    """Seeds ``1,2,3`` or a range ``1-10`` (inclusive), or both: ``1-3,7``; a seed may
    not repeat."""
    seeds: list[int] = []
    for part in (p.strip() for p in text.split(",")):
        first, sep, last = part.partition("-")
        try:
            lo = seed_int(first)
            hi = seed_int(last) if sep else lo
        except argparse.ArgumentTypeError:
            lo, hi = 0, -1
        if lo > hi:
            raise argparse.ArgumentTypeError(f"{text} is not allowed: seeds in [0, 2^31), "
                                             "comma-separated, A-B for a range")
        seeds += list(range(lo, hi + 1))
    if len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: a seed repeats")
    return seeds
