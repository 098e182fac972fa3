"""``arzsumo study inlet``: the command line of :mod:`arzsumo_studies.identify.inlet`, mapped onto
its :class:`~arzsumo_studies.identify.inlet.InletOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.cli.options import add_output
from arzsumo_studies.common import positive_int
from arzsumo_studies.identify.inlet import NAME, PAGE, InletOptions, run_inlet


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The inlet study's options."""
    parser.add_argument("--runs", type=Path, metavar="DIR",
                        help="cached identification runs (default: $ARZSUMO_CACHE/"
                             "identify-runs)")
    parser.add_argument("--last", type=positive_int, default=5,
                        help="replay the most recent N runs")
    parser.add_argument("--scenario", type=Path, default=None, metavar="SCENARIO.toml",
                        help="the parameters replayed under (default: the former default, "
                             "lateral_files)")
    parser.add_argument("--workers", type=positive_int, default=1, metavar="N",
                        help="local processes (1: in this process)")
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> InletOptions:
    """The study's options as the command line gave them."""
    return InletOptions(runs=args.runs, last=args.last, scenario=args.scenario,
                        workers=args.workers, out=args.out, docs=args.docs)


def run(args: argparse.Namespace) -> int:
    """Replay every run under every inlet, write the table and print it."""
    print(run_inlet(options(args)).text)
    return 0
