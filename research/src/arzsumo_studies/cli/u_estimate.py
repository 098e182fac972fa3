"""``arzsumo study u-estimate``: the command line of :mod:`arzsumo_studies.estimation.u_estimate`,
mapped onto its :class:`~arzsumo_studies.estimation.u_estimate.UEstimateOptions`."""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.options import add_output, add_runs, plots_wanted
from arzsumo_studies.common import positive_float, print_list
from arzsumo_studies.estimation.u_estimate import (
    NAME,
    PAGE,
    UEstimateOptions,
    design,
    run_u_estimate,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    add_runs(parser, seeds="42")
    parser.add_argument("--warmup", type=positive_float, default=150.0, help="s")
    parser.add_argument("--horizon", type=positive_float, default=120.0,
                        help="control horizon, s")
    parser.add_argument("--controller", default="backstepping",
                        help="the law (a controller with a continuous U)")
    add_output(parser, NAME, PAGE)


def options(args: argparse.Namespace) -> UEstimateOptions:
    """The study's options as the command line gave them."""
    return UEstimateOptions(seeds=tuple(args.seeds), warmup_s=args.warmup,
                            horizon_s=args.horizon, controller=args.controller,
                            out=args.out, docs=args.docs, plots=plots_wanted(args),
                            workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise run the sweep (resumable), write the table and the
    figure, and print the table."""
    opts = options(args)
    if args.list:
        return print_list([r.run_id for r in design(opts).runs()])
    result = run_u_estimate(opts, progress=not args.quiet)
    print(result.text)
    return result.code
