"""``arzsumo study fill``: the command line of :mod:`arzsumo_studies.sumo_map.fill`, mapped onto
its :class:`~arzsumo_studies.sumo_map.fill.FillOptions`."""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.options import add_measured_window, add_output, add_runs
from arzsumo_studies.common import non_negative_float, number_list, positive_float, print_list
from arzsumo_studies.sumo_map.fill import NAME, PAGE, FillOptions, design, run_fill


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The fill study's options."""
    parser.add_argument("--holds", nargs="+", default=["3750:850"], metavar="HV:AV",
                        help="hold demands, veh/h")
    parser.add_argument("--fill-h", type=non_negative_float, default=4200.0,
                        help="HV fill demand, veh/h")
    parser.add_argument("--fill-a", type=non_negative_float, default=1300.0,
                        help="AV fill demand, veh/h")
    parser.add_argument("--fill", type=non_negative_float, default=600.0,
                        help="fill phase, s")
    parser.add_argument("--greens", type=number_list, default=[0.5],
                        help="nominal green shares (default: 0.5)")
    parser.add_argument("--sigmas", type=number_list, default=[0.5],
                        help="Krauss sigma of the HVs (default: 0.5)")
    add_runs(parser, seeds="1")
    parser.add_argument("--approach", type=positive_float, default=2500.0,
                        help="buffer length before x = 0, m")
    add_measured_window(parser, warmup_s=600.0)
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> FillOptions:
    """The study's options as the command line gave them."""
    return FillOptions(holds=tuple(args.holds), fill_h_veh_h=args.fill_h,
                       fill_a_veh_h=args.fill_a, fill_s=args.fill, greens=tuple(args.greens),
                       sigmas=tuple(args.sigmas), seeds=tuple(args.seeds),
                       approach_m=args.approach, warmup_s=args.warmup,
                       measured_s=args.measured, step_s=args.step, out=args.out,
                       docs=args.docs, workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise run the missing points, write the table (and the
    page with ``--docs``) and print it."""
    opts = options(args)
    if args.list:
        return print_list([r.run_id for r in design(opts)])
    print(run_fill(opts, progress=not args.quiet).text)
    return 0
