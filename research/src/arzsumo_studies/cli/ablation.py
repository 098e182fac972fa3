"""``arzsumo study ablation``: the command line of :mod:`arzsumo_studies.ablation.study`, mapped
onto its :class:`~arzsumo_studies.ablation.study.AblationOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.ablation.study import (
    NAME,
    PAGE,
    STEP_NAMES,
    AblationOptions,
    design,
    run_ablation,
)
from arzsumo_studies.cli.options import add_output, add_runs, plots_wanted


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The ablation's options."""
    parser.add_argument("--steps", default=",".join(STEP_NAMES),
                        help="comma-separated steps to run (identified runs first)")
    add_runs(parser, seeds="1-10")
    parser.add_argument("--report", action="store_true",
                        help="run nothing: assemble the table from the steps in --out")
    parser.add_argument("--legacy", type=Path, metavar="CSV",
                        help="an earlier evaluation.csv listed first as step 'legacy'")
    add_output(parser, NAME, PAGE)


def options(args: argparse.Namespace) -> AblationOptions:
    """The study's options as the command line gave them."""
    return AblationOptions(steps=tuple(n.strip() for n in args.steps.split(",") if n.strip()),
                           seeds=tuple(args.seeds), report=args.report, legacy=args.legacy,
                           out=args.out, docs=args.docs, plots=plots_wanted(args),
                           workers=args.workers, scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the steps' evaluations; otherwise run the steps asked for, then write
    the table (and the page with ``--docs``) and print it."""
    opts = options(args)
    if args.list:
        for line in design(opts):
            print(line)
        return 0
    result = run_ablation(opts, progress=not args.quiet)
    print(result.text)
    return result.code
