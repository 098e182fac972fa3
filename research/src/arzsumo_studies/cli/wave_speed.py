"""``arzsumo study wave-speed``: the command line of :mod:`arzsumo_studies.sumo_map.wave_speed`,
mapped onto its :class:`~arzsumo_studies.sumo_map.wave_speed.WaveSpeedOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.cli.options import add_output, add_runs, add_study_scenario
from arzsumo_studies.common import print_list
from arzsumo_studies.sumo_map.wave_speed import NAME, PAGE, WaveSpeedOptions, design, run_wave_speed


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The wave-speed study's options."""
    add_study_scenario(parser, "run")
    parser.add_argument("--controllers", default="open,etc",
                        help="comma-separated controllers")
    add_runs(parser, seeds="42")
    parser.add_argument("--from", dest="source", type=Path, nargs="+", metavar="DIR",
                        help="read these arzsumo run results instead of running SUMO")
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> WaveSpeedOptions:
    """The study's options as the command line gave them."""
    return WaveSpeedOptions(
        scenario=args.scenario, seeds=tuple(args.seeds),
        controllers=tuple(c.strip() for c in args.controllers.split(",") if c.strip()),
        source=tuple(args.source or ()), out=args.out, docs=args.docs,
        workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise run (or read) and write the table of lags and
    speeds, and print it."""
    opts = options(args)
    runs = design(opts)
    if args.list:
        return print_list([r.run_id for r in runs],
                          ("--from", args.source) if args.source else None)
    print(run_wave_speed(opts, progress=not args.quiet).text)
    return 0
