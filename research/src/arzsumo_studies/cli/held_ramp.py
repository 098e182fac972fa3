"""``arzsumo study held-ramp``: the command line of :mod:`arzsumo_studies.ablation.held_ramp`,
mapped onto its :class:`~arzsumo_studies.ablation.held_ramp.HeldRampOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo_studies.ablation import study as ablation
from arzsumo_studies.ablation.held_ramp import NAME, PAGE, HeldRampOptions, design, run_held_ramp
from arzsumo_studies.cli.options import add_output, add_runs, plots_wanted
from arzsumo_studies.common import RESULTS_DIR


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The held-ramp study's options."""
    parser.add_argument("--ablation", type=Path, default=RESULTS_DIR / ablation.NAME,
                        metavar="DIR", help="the ablation directory holding the meter step")
    add_runs(parser, seeds="1-10")
    parser.add_argument("--report", action="store_true",
                        help="run nothing: the table from the evaluations already there")
    add_output(parser, NAME, PAGE)


def options(args: argparse.Namespace) -> HeldRampOptions:
    """The study's options as the command line gave them."""
    return HeldRampOptions(ablation=args.ablation, seeds=tuple(args.seeds),
                           report=args.report, out=args.out, docs=args.docs,
                           plots=plots_wanted(args), workers=args.workers,
                           scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the evaluation; otherwise evaluate the held ramp (resumable), pair the
    meter step against it and print the table."""
    opts = options(args)
    if args.list:
        print("\n".join(design(opts)))
        return 0
    result = run_held_ramp(opts, progress=not args.quiet)
    print(result.text)
    return result.code
