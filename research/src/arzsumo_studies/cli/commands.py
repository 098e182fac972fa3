"""The research commands: ``arzsumo study NAME`` and ``arzsumo premise`` (entry points of
the group ``arzsumo.commands``, which the tool's CLI lists after its own commands), and
``arzsumo-study NAME``, the same studies under a command of their own."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from arzsumo.cli import run_command
from arzsumo.cli.args import Parser
from arzsumo_studies.cli import premise, study
from arzsumo_studies.cli.catalog import STUDIES


def register_study(sub: argparse._SubParsersAction) -> None:
    """Add ``study`` and its sub-commands to the ``arzsumo`` parser."""
    study.register(sub)


def register_premise(sub: argparse._SubParsersAction) -> None:
    """Add ``premise`` to the ``arzsumo`` parser."""
    premise.register(sub)


def build_parser() -> argparse.ArgumentParser:
    """The ``arzsumo-study`` parser: one sub-command per study, and ``premise``."""
    parser = Parser(prog="arzsumo-study",
                    description="This project's studies on arzsumo: experiments built on "
                                "the twin and SUMO, each writing its results and report to "
                                "--out (also 'arzsumo study NAME').",
                    epilog="'arzsumo-study NAME --help' shows a study's options.")
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    names = parser.add_subparsers(dest="study", required=True, metavar="STUDY")
    for entry in STUDIES.values():
        s = names.add_parser(entry.name, help=entry.help, description=entry.help)
        entry.add_arguments(s)
        s.set_defaults(func=entry.run)
    premise.register(names)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``arzsumo-study ARGV``; return the exit code."""
    return run_command(build_parser(), argv, "arzsumo-study")
