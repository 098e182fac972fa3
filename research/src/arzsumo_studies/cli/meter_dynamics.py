"""``arzsumo study meter-dynamics``: the command line of
:mod:`arzsumo_studies.sumo_map.meter_dynamics`, mapped onto its
:class:`~arzsumo_studies.sumo_map.meter_dynamics.MeterDynamicsOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.cli.options import add_output, add_runs, plots_wanted
from arzsumo_studies.common import fraction_list, positive_float, print_list
from arzsumo_studies.sumo_map.meter_dynamics import (
    GREENS,
    NAME,
    PAGE,
    MeterDynamicsOptions,
    design,
    run_meter_dynamics,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The meter-dynamics study's options."""
    add_runs(parser, seeds="1-3")
    parser.add_argument("--warmup", type=positive_float, default=600.0,
                        help="fill and warm-up at green share 0.5, s")
    parser.add_argument("--base", type=positive_float, default=60.0,
                        help="s more at 0.5 before the steps")
    # the meter runs green shares in [0, 1] (0: all red, 1: all green); the steps drive
    # it directly, past the scenario's green_share_min/max, so the option is the check
    parser.add_argument("--greens", type=fraction_list, default=list(GREENS),
                        help="the green shares of the steps, comma-separated, each in "
                             f"[0, 1] (default: {','.join(map(str, GREENS))})")
    parser.add_argument("--hold", type=positive_float, default=102.0,
                        help="s per step (17 cycles of 6 s)")
    parser.add_argument("--pre", type=positive_float, default=60.0,
                        help="s before each change in its fit")
    parser.add_argument("--settled", type=positive_float, default=60.0,
                        help="last s of each hold averaged for the static levels")
    parser.add_argument("--series", type=Path, metavar="CSV",
                        help="fit this series (a series.csv of this study) instead of "
                             "running SUMO")
    add_output(parser, NAME, PAGE)


def options(args: argparse.Namespace) -> MeterDynamicsOptions:
    """The study's options as the command line gave them."""
    return MeterDynamicsOptions(
        seeds=tuple(args.seeds), warmup_s=args.warmup, base_s=args.base,
        greens=tuple(args.greens), hold_s=args.hold, pre_s=args.pre,
        settled_s=args.settled, series=args.series, out=args.out, docs=args.docs,
        plots=plots_wanted(args), workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs (none with ``--series``); otherwise run the steps (or read
    ``--series``), fit, write (and publish with ``--docs``) and print the tables."""
    opts = options(args)
    runs = design(opts)
    if args.list:
        return print_list([r.run_id for r in runs],
                          None if args.series is None else ("--series", args.series))
    print(run_meter_dynamics(opts, progress=not args.quiet).text)
    return 0
