"""``arzsumo study NAME [OPTIONS]``: one sub-command per study of
:data:`arzsumo_studies.cli.catalog.STUDIES`.

Each sub-command gets the study's options (``Study.add_arguments``: every study declares
its own, ``--out`` defaulting to ``results/studies/NAME``, from the shared helpers of
:mod:`arzsumo_studies.common`); running it calls ``Study.run``, whose return value is the
exit code.
"""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.catalog import STUDIES, Study


def _epilog(studies: dict[str, Study]) -> str:
    if not studies:
        return "no studies are registered yet (arzsumo_studies.cli.catalog.STUDIES is empty)"
    return "'arzsumo study NAME --help' shows a study's options."


def register(sub: argparse._SubParsersAction, studies: dict[str, Study] | None = None
             ) -> None:
    """Add ``study`` and its sub-commands (``studies``, default the catalogue's) to the
    top-level parser."""
    studies = STUDIES if studies is None else studies
    p = sub.add_parser("study", help="run a study of the catalogue ('arzsumo study --help' "
                                     "lists them)",
                       description="Run one of the studies of the catalogue: experiments "
                                   "built on the twin and SUMO, each writing its results "
                                   "and report to --out.", epilog=_epilog(studies))
    names = p.add_subparsers(dest="study", required=True, metavar="STUDY")
    for study in studies.values():
        s = names.add_parser(study.name, help=study.help, description=study.help)
        study.add_arguments(s)
        s.set_defaults(func=study.run)
