"""``arzsumo study estimation-layouts``: the command line of
:mod:`arzsumo_studies.estimation.layouts`, mapped onto its
:class:`~arzsumo_studies.estimation.layouts.LayoutsOptions`."""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.options import (
    add_output,
    add_runs,
    add_scenario_times,
    add_study_scenario,
)
from arzsumo_studies.common import print_list
from arzsumo_studies.estimation.layouts import (
    NAME,
    PAGE,
    LayoutsOptions,
    run_layouts,
    study_runs,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The layout study's options."""
    add_study_scenario(parser)
    add_runs(parser, seeds="1-5")
    add_scenario_times(parser)
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> LayoutsOptions:
    """The study's options as the command line gave them."""
    return LayoutsOptions(scenario=args.scenario, seeds=tuple(args.seeds),
                          warmup_s=args.warmup, horizon_s=args.horizon, out=args.out,
                          docs=args.docs, workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise record the missing seeds, score every layout and
    method, write the table and print it."""
    opts = options(args)
    if args.list:
        return print_list([r.run_id for r in study_runs(opts)])
    print(run_layouts(opts, progress=not args.quiet).text)
    return 0
