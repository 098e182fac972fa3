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
from typing import Any, NoReturn

#: exit code of a user error (argparse's own, and the CLI's for ArzsumoError)
EXIT_USAGE = 2
#: SUMO's seed range
SEED_LIMIT = 2**31


def _number(text: str, kind: type) -> Any:
    try:
        value = kind(text)
    except ValueError:
        what = "an integer" if kind is int else "a number"
        raise argparse.ArgumentTypeError(f"{text} is not allowed: {what}") from None
    return value


def positive_float(text: str) -> float:
    """A finite number > 0 (times, periods, design constants)."""
    value = _number(text, float)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: a finite number > 0")
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0 (lengths that may be absent)."""
    value = _number(text, float)
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: a finite number >= 0")
    return value


def positive_int(text: str) -> int:
    """An integer >= 1 (workers, jobs)."""
    value = _number(text, int)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: an integer >= 1")
    return value


def seed_int(text: str) -> int:
    """A random seed: an integer in [0, 2^31) (SUMO's range)."""
    value = _number(text, int)
    if not 0 <= value < SEED_LIMIT:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: an integer in [0, 2^31)")
    return value


def cells_int(text: str) -> int:
    """A grid size: an integer >= 4."""
    value = _number(text, int)
    if value < 4:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: an integer >= 4")
    return value


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
