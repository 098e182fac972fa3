"""Argument checking and help layout shared by every ``arzsumo`` command.

Nonsense on the command line (a negative horizon, zero workers, a negative seed) is
refused by argparse itself through the ``type=`` helpers below; :class:`Parser` prints
that refusal, like every other user error, as ONE line ``arzsumo: error: ...`` and exits
with code 2 (no usage block: ``arzsumo CMD --help`` shows it). :class:`HelpFormatter`
shows defaults in every help text.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable
from typing import Any, NoReturn

from arzsumo.errors import EXIT_USAGE

#: SUMO's seed range
SEED_LIMIT = 2**31


def _number(text: str, kind: type) -> Any:
    try:
        value = kind(text)
    except ValueError:
        what = "an integer" if kind is int else "a number"
        raise argparse.ArgumentTypeError(f"{text} is not allowed: {what}") from None
    return value


def _checked(name: str, kind: type, ok: Callable[[Any], bool], allowed: str,
             doc: str) -> Callable[[str], Any]:
    """An argparse ``type=``: ``text`` read as ``kind`` and kept when ``ok``; otherwise
    refused as "TEXT is not allowed: ALLOWED"."""
    def parse(text: str) -> Any:
        value = _number(text, kind)
        if not ok(value):
            raise argparse.ArgumentTypeError(f"{text} is not allowed: {allowed}")
        return value

    parse.__name__ = parse.__qualname__ = name
    parse.__doc__ = doc
    return parse


positive_float = _checked("positive_float", float, lambda v: math.isfinite(v) and v > 0,
                          "a finite number > 0",
                          "A finite number > 0 (times, periods, design constants).")
non_negative_float = _checked("non_negative_float", float,
                              lambda v: math.isfinite(v) and v >= 0, "a finite number >= 0",
                              "A finite number >= 0 (lengths that may be absent).")
negative_float = _checked("negative_float", float, lambda v: math.isfinite(v) and v < 0,
                          "a finite number < 0",
                          "A finite number < 0 (speeds of waves that travel upstream).")
positive_int = _checked("positive_int", int, lambda v: v >= 1, "an integer >= 1",
                        "An integer >= 1 (workers, jobs).")
non_negative_int = _checked("non_negative_int", int, lambda v: v >= 0, "an integer >= 0",
                            "An integer >= 0 (counts that may be zero).")
seed_int = _checked("seed_int", int, lambda v: 0 <= v < SEED_LIMIT, "an integer in [0, 2^31)",
                    "A random seed: an integer in [0, 2^31) (SUMO's range).")
cells_int = _checked("cells_int", int, lambda v: v >= 4, "an integer >= 4",
                     "A grid size: an integer >= 4.")


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter,
                    argparse.RawDescriptionHelpFormatter):
    """Shows ``(default: X)`` unless the default is unset or the help already gives it;
    keeps the line breaks of descriptions and epilogs."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if action.default in (None, False, argparse.SUPPRESS) or "default" in text:
            return text
        return super()._get_help_string(action)


_OPTION_VALUE = re.compile(r"^argument (?:\S+/)?(\S+): (\S+ is not allowed: .*)$")


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line, ``arzsumo: error: ...``, exit 2.

    Subcommand parsers are of this class too (argparse makes them with the parent's
    class) and get :class:`HelpFormatter`.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        m = _OPTION_VALUE.match(message)
        if m:  # "argument --horizon: -5 is not allowed: ..." -> "--horizon = -5 is ..."
            message = f"{m.group(1)} = {m.group(2)}"
        self.exit(EXIT_USAGE, f"arzsumo: error: {message} (see '{self.prog} --help')\n")


def seed_list(text: str) -> list[int]:
    """Comma-separated seeds; ``A-B`` for a range (inclusive)."""
    seeds: list[int] = []
    for part in (p.strip() for p in text.split(",")):
        first, sep, last = part.partition("-")
        try:
            lo = seed_int(first)
            hi = seed_int(last) if sep else lo
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"{text} is not allowed: seeds in [0, 2^31), "
                                             "comma-separated, A-B for a range") from None
        seeds += list(range(lo, hi + 1))
    return seeds
