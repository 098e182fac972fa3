"""``arzsumo study reach``: the command line of :mod:`arzsumo_studies.control.reach`,
mapped onto its :class:`~arzsumo_studies.control.reach.ReachOptions`."""

from __future__ import annotations

import argparse

from arzsumo.argtypes import positive_float, positive_int
from arzsumo_studies.cli.options import add_output, plots_wanted
from arzsumo_studies.control import reach as study


def condition(text: str) -> tuple[str, str]:
    """``NAME=GLOB`` read as (name, glob), split at the first ``=`` (a glob may hold
    more, as in ``controller=open,seed=*``); refused without a name or a glob."""
    name, sep, pattern = text.partition("=")
    if not (sep and name.strip() and pattern.strip()):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: NAME=GLOB, e.g. "
                                         "'open=OUT/regulation/runs/controller=open,seed=*'")
    return name.strip(), pattern.strip()


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    parser.add_argument("--runs", type=condition, action="append", metavar="NAME=GLOB",
                        help="a condition, repeatable: its name and a glob of its run "
                             "directories (each with cells.parquet, periods.parquet, "
                             "summary.json, as `arzsumo run --out` writes them), pooled")
    parser.add_argument("--block-s", type=positive_float, default=5.0, metavar="S",
                        help="the blocks the speeds and flows are averaged over, s "
                             "(default: 5)")
    parser.add_argument("--max-runs", type=positive_int, metavar="N",
                        help="the first N run directories of each condition, by seed "
                             "(default: all)")
    add_output(parser, study.NAME, study.PAGE)


def options(args: argparse.Namespace) -> study.ReachOptions:
    """The study's options as the command line gave them."""
    return study.ReachOptions(runs=tuple(args.runs or ()), block_s=args.block_s,
                              max_runs=args.max_runs, out=args.out, docs=args.docs,
                              plots=plots_wanted(args))


def run(args: argparse.Namespace) -> int:
    """Read the conditions' runs, write the table and the figure; print the table."""
    print(study.run_reach(options(args)).text)
    return 0
