"""``arzsumo study premise-map``: the command line of :mod:`arzsumo_studies.premise.map_study`,
mapped onto its :class:`~arzsumo_studies.premise.map_study.MapOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.cli.options import add_output, add_runs, plots_wanted
from arzsumo_studies.common import print_list
from arzsumo_studies.premise.map_points import NAME, POINTS
from arzsumo_studies.premise.map_study import PAGE, MapOptions, design, run_map
from arzsumo_studies.premise.map_tables import map_markdown, theory_markdown


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The premise map's options."""
    parser.add_argument("--scenario", type=Path, metavar="SCENARIO.toml",
                        help="base scenario every point changes (default: the former "
                             "default, lateral_files)")
    parser.add_argument("--points", default=None, metavar="LIST",
                        help="comma-separated point names (default: all: "
                             + ", ".join(p.name for p in POINTS) + ")")
    parser.add_argument("--window", type=float, default=540.0,
                        help="baseline and pulse window after the warm-up, s")
    parser.add_argument("--pulse-s", type=float, default=25.0,
                        help="the pulse: the meter at its least plan this long, s")
    parser.add_argument("--no-pulse", action="store_true",
                        help="baselines only (the pulse gate is then not measured)")
    add_runs(parser, seeds="1,2")
    add_output(parser, NAME, PAGE)
    parser.add_argument("--page", default=PAGE, metavar="NAME",
                        help=f"the results page --docs regenerates, DIR/NAME.md (default: "
                             f"{PAGE}; e.g. premise_map_car_following for that axis)")


def options(args: argparse.Namespace) -> MapOptions:
    """The study's options as the command line gave them."""
    points = None if args.points is None else tuple(
        n.strip() for n in args.points.split(",") if n.strip()) or (args.points,)
    return MapOptions(scenario=args.scenario, points=points, seeds=tuple(args.seeds),
                      window_s=args.window, pulse_s=args.pulse_s, pulses=not args.no_pulse,
                      out=args.out, docs=args.docs, page=args.page,
                      plots=plots_wanted(args), workers=args.workers,
                      scheduler=args.scheduler, progress=not args.quiet)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise run the map and print its two tables."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    result = run_map(opts)
    print(map_markdown(result.wide))
    print(theory_markdown(result.wide))
    return 0
