"""``arzsumo study loop-speed``: the command line of :mod:`arzsumo_studies.estimation.loop_speed`,
mapped onto its :class:`~arzsumo_studies.estimation.loop_speed.LoopSpeedOptions`."""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.options import add_output, add_runs, add_study_scenario
from arzsumo_studies.common import positive_float, print_list
from arzsumo_studies.estimation.loop_speed import (
    METHODS,
    NAME,
    PAGE,
    LoopSpeedOptions,
    design,
    run_loop_speed,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The loop-speed study's options."""
    add_study_scenario(parser)
    add_runs(parser, seeds="1")
    parser.add_argument("--horizon", type=positive_float, default=300.0,
                        help="control horizon recorded, s")
    parser.add_argument("--method", default="smoothing", choices=METHODS,
                        help="the estimator")
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> LoopSpeedOptions:
    """The study's options as the command line gave them."""
    return LoopSpeedOptions(scenario=args.scenario, seeds=tuple(args.seeds),
                            horizon_s=args.horizon, method=args.method, out=args.out,
                            docs=args.docs, workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise record (or reuse) the runs, replay both loop
    speeds, write and print the table."""
    opts = options(args)
    if args.list:
        return print_list([r.run_id for r in design(opts)])
    print(run_loop_speed(opts, progress=not args.quiet).text)
    return 0
