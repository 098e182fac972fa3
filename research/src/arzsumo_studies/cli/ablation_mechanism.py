"""``arzsumo study ablation-mechanism``: the command line of
:mod:`arzsumo_studies.ablation.mechanism`, mapped onto its
:class:`~arzsumo_studies.ablation.mechanism.MechanismOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.ablation import study as ablation
from arzsumo_studies.ablation.mechanism import NAME, PAGE, MechanismOptions, run_mechanism
from arzsumo_studies.cli.options import add_output, plots_wanted
from arzsumo_studies.common import RESULTS_DIR


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The mechanism study's options."""
    parser.add_argument("--ablation", type=Path, default=RESULTS_DIR / ablation.NAME,
                        metavar="DIR", help="the ablation directory (arzsumo study "
                                            "ablation --out)")
    parser.add_argument("--levels", type=Path, metavar="CSV",
                        help="static outflow levels of held plans drawn on the map (the "
                             "levels.csv of arzsumo study meter-dynamics)")
    add_output(parser, NAME, PAGE)


def options(args: argparse.Namespace) -> MechanismOptions:
    """The study's options as the command line gave them."""
    return MechanismOptions(ablation=args.ablation, levels=args.levels, out=args.out,
                            docs=args.docs, plots=plots_wanted(args))


def run(args: argparse.Namespace) -> int:
    """Collect, pair, fit; write the tables, figures and (``--docs``) the page; print the
    means per step and controller and the table."""
    result = run_mechanism(options(args))
    print(result.means.to_string())
    print(result.text)
    return 0
