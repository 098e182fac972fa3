"""``arzsumo study control``: the command line of :mod:`arzsumo_studies.control.study`, mapped
onto its :class:`~arzsumo_studies.control.study.ControlOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.errors import EXIT_SOME_FAILED
from arzsumo.resources import default_scenario
from arzsumo_studies.cli.options import (
    add_output,
    add_records,
    add_runs,
    plots_wanted,
    recorded_runs,
)
from arzsumo_studies.common import names_among, print_list
from arzsumo_studies.control.study import (
    ALL_EXPERIMENTS,
    EXPERIMENTS,
    JUDGED,
    NAME,
    PAGE,
    ControlOptions,
    design,
    run_control,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The control study's options."""
    parser.add_argument("--scenario", type=Path,
                        default=default_scenario(), metavar="FILE",
                        help="the base scenario (default: the shipped default)")
    parser.add_argument("--controllers", default=",".join(JUDGED),
                        help="comma-separated controllers (default: %(default)s)")
    parser.add_argument("--experiments", default=",".join(EXPERIMENTS),
                        help="comma-separated, of regulation, disturbance, merge-slowdown "
                        "(the slowdown on the merge's edge instead of the edge past it; "
                        "default: regulation,disturbance)")
    parser.add_argument("--runs-from", type=Path, action="append", default=[],
                        metavar="DIR", help="an earlier evaluation or sweep (repeatable): "
                        "a controller whose runs on all the seeds are there is taken from "
                        "there (arzsumo evaluate --runs-from)")
    add_records(parser)
    add_runs(parser, seeds="1-20")
    add_output(parser, NAME, PAGE)
    parser.add_argument("--page", default=PAGE, metavar="NAME",
                        help="the results page --docs regenerates, DIR/NAME.md with its "
                             "files in DIR/NAME/ (default: %(default)s, the default's)")


def options(args: argparse.Namespace) -> ControlOptions:
    """The study's options as the command line gave them."""
    return ControlOptions(recorded_runs(args), scenario=args.scenario,
                          controllers=tuple(args.controllers.split(",")),
                          experiments=tuple(names_among(args.experiments, ALL_EXPERIMENTS,
                                                        "--experiments")),
                          out=args.out, docs=args.docs, page=args.page,
                          plots=plots_wanted(args))


def run(args: argparse.Namespace) -> int:
    """``--list``: the experiments; otherwise run them and print ``control.md``."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    result = run_control(opts)
    if result.text:
        print(result.text)
    return 0 if result.complete else EXIT_SOME_FAILED
