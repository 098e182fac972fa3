"""``arzsumo study approach``: the command line of :mod:`arzsumo_studies.sumo_map.approach`, mapped
onto its :class:`~arzsumo_studies.sumo_map.approach.ApproachOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.cli.options import add_measured_window, add_output, add_runs, plots_wanted
from arzsumo_studies.common import fraction, number_list, positive_float, print_list
from arzsumo_studies.sumo_map.approach import (
    AV_SHARE,
    NAME,
    PAGE,
    ApproachOptions,
    design,
    run_approach,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The approach study's options."""
    parser.add_argument("--demands", type=number_list, default=[4400, 4800, 5200, 5664, 6000],
                        help="mainline demands HV + AV, veh/h (default: 4400,4800,5200,"
                             "5664,6000)")
    parser.add_argument("--greens", type=number_list, default=[0.3, 0.5, 0.7, 0.9],
                        help="nominal green shares (default: 0.3,0.5,0.7,0.9)")
    parser.add_argument("--sigmas", type=number_list, default=[0.5],
                        help="Krauss sigma of the HVs (default: 0.5)")
    add_runs(parser, seeds="1")
    parser.add_argument("--approach", type=positive_float, default=1500.0,
                        help="buffer length before x = 0, m")
    parser.add_argument("--empty-start", action="store_true",
                        help="start with an empty section (default: a congested one)")
    add_measured_window(parser, warmup_s=150.0)
    parser.add_argument("--av-share", type=fraction, default=AV_SHARE,
                        help="AV share of the mainline demand (default: 0.275)")
    parser.add_argument("--from", dest="source", type=Path, metavar="CSV",
                        help="draw the map of this table instead of running SUMO")
    add_output(parser, NAME, PAGE)


def options(args: argparse.Namespace) -> ApproachOptions:
    """The study's options as the command line gave them."""
    return ApproachOptions(
        demands=tuple(args.demands), greens=tuple(args.greens), sigmas=tuple(args.sigmas),
        seeds=tuple(args.seeds), approach_m=args.approach, initial=not args.empty_start,
        warmup_s=args.warmup, measured_s=args.measured, step_s=args.step,
        av_share=args.av_share, source=args.source, out=args.out, docs=args.docs,
        plots=plots_wanted(args), workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs (none with ``--from``); otherwise run the missing points (or
    read ``--from``), write the table and the map, and print the summary."""
    opts = options(args)
    runs = design(opts)
    if args.list:
        return print_list([r.run_id for r in runs],
                          None if args.source is None else ("--from", args.source))
    print(run_approach(opts, progress=not args.quiet).text)
    return 0
