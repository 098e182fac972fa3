"""Argument checking and help layout shared by every ``arzsumo`` command: a refused
argument (the ``type=`` checks of :mod:`arzsumo.argtypes`) is one line, exit code 2."""

from __future__ import annotations

import argparse
import re
from typing import Any, NoReturn

from arzsumo.errors import EXIT_USAGE


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
    """An ArgumentParser whose errors are one line, ``arzsumo: error: ...``, exit 2; its
    subcommand parsers (argparse makes them of the parent's class) too."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        m = _OPTION_VALUE.match(message)
        if m:  # "argument --horizon: -5 is not allowed: ..." -> "--horizon = -5 is ..."
            message = f"{m.group(1)} = {m.group(2)}"
        self.exit(EXIT_USAGE, f"arzsumo: error: {message} (see '{self.prog} --help')\n")
