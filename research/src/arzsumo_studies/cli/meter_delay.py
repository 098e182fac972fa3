"""``arzsumo study meter-delay``: the command line of :mod:`arzsumo_studies.control.meter_delay`,
mapped onto its :class:`~arzsumo_studies.control.meter_delay.MeterDelayOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.cli.options import add_output
from arzsumo_studies.common import RESULTS_DIR, names_among
from arzsumo_studies.control.meter_delay import (
    NAME,
    PAGE,
    PAIRED,
    MeterDelayOptions,
    run_meter_delay,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    parser.add_argument("--sumo", type=Path, metavar="DIR", action="append",
                        help="the --out of `arzsumo study control`, repeatable: the runs of "
                             f"several (default: {RESULTS_DIR / 'control'})")
    parser.add_argument("--experiment", default="regulation",
                        help="the experiment whose runs are paired (default: regulation)")
    parser.add_argument("--controllers", default=",".join(PAIRED),
                        help=f"comma-separated, of {', '.join(PAIRED)} (default: all)")
    add_output(parser, NAME, PAGE, plots=False)


def options(args: argparse.Namespace) -> MeterDelayOptions:
    """The study's options as the command line gave them."""
    controllers = tuple(names_among(args.controllers, PAIRED, "--controllers"))
    return MeterDelayOptions(sumo=tuple(args.sumo or [RESULTS_DIR / "control"]),
                             experiment=args.experiment, controllers=controllers,
                             out=args.out, docs=args.docs)


def run(args: argparse.Namespace) -> int:
    """The paired events of every seed, their summary, the page block; the text printed."""
    print(run_meter_delay(options(args)).text)
    return 0
