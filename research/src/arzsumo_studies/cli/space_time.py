"""``arzsumo study space-time``: the command line of :mod:`arzsumo_studies.control.space_time`,
mapped onto its :class:`~arzsumo_studies.control.space_time.SpaceTimeOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.argtypes import non_negative_int
from arzsumo_studies.cli.options import add_output, add_scenario_times
from arzsumo_studies.control import space_time as study
from arzsumo_studies.control.study import ALL_EXPERIMENTS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    parser.add_argument("--scenario", type=Path, metavar="SCENARIO.toml",
                        help="the base scenario (default: the shipped default)")
    parser.add_argument("--seed", type=non_negative_int, default=1,
                        help="the SUMO seed (default: 1)")
    parser.add_argument("--controllers", default="open,etc", metavar="LIST",
                        help="two to four controllers, drawn left to right (default: "
                             "open,etc)")
    parser.add_argument("--experiment", choices=ALL_EXPERIMENTS, default="regulation",
                        help="the control study's experiment (default: regulation)")
    add_scenario_times(parser)      # with other times the runs are not the study's
    parser.add_argument("--quiet", action="store_true", help="no line per run")
    add_output(parser, study.NAME, study.PAGE, plots=False)
    parser.add_argument("--page", default=study.PAGE,
                        help=f"the page's name under --docs (default: {study.PAGE})")


def options(args: argparse.Namespace) -> study.SpaceTimeOptions:
    """The study's options as the command line gave them."""
    return study.SpaceTimeOptions(
        scenario=args.scenario, seed=args.seed,
        controllers=tuple(c.strip() for c in args.controllers.split(",") if c.strip()),
        experiment=args.experiment, warmup=args.warmup, horizon=args.horizon,
        out=args.out, docs=args.docs, page=args.page, progress=not args.quiet)


def run(args: argparse.Namespace) -> int:
    """Run (or reuse) the runs, draw the figures, print where they are."""
    result = study.run_space_time(options(args))
    for path in result.figures:
        print(f"written: {path}")
    return 0
