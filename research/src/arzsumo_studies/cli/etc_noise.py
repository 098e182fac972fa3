"""``arzsumo study etc-noise``: the command line of :mod:`arzsumo_studies.control.etc_noise`,
mapped onto its :class:`~arzsumo_studies.control.etc_noise.EtcNoiseOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.resources import default_scenario
from arzsumo_studies.cli.options import add_output, add_runs
from arzsumo_studies.common import number_list, print_list
from arzsumo_studies.control.etc_noise import (
    LEVELS_PCT,
    NAME,
    PAGE,
    EtcNoiseOptions,
    design,
    run_etc_noise,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    parser.add_argument("--scenario", type=Path,
                        default=default_scenario(), metavar="FILE",
                        help="the scenario whose twin is run (default: the shipped default)")
    parser.add_argument("--levels", type=number_list, default=number_list(LEVELS_PCT),
                        metavar="LIST", help="relative noise sd of the fields, %% "
                                             f"(default: {LEVELS_PCT})")
    parser.add_argument("--sumo", type=Path, metavar="DIR",
                        help="the --out of `arzsumo study control`: SUMO's point")
    add_runs(parser, seeds="1-10")
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> EtcNoiseOptions:
    """The study's options as the command line gave them."""
    return EtcNoiseOptions(scenario=args.scenario, levels=tuple(args.levels),
                           sumo=args.sumo, seeds=tuple(args.seeds), out=args.out,
                           docs=args.docs, workers=args.workers)


def run(args: argparse.Namespace) -> int:
    """``--list``: the twin runs; otherwise every (law, level, seed) twin run, the
    tables, SUMO's point, the text printed."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    print(run_etc_noise(opts, progress=not args.quiet).text)
    return 0
