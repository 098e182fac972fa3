"""``arzsumo study control-ablation``: the command line of
:mod:`arzsumo_studies.control.ablation`, mapped onto its
:class:`~arzsumo_studies.control.ablation.AblationOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.errors import EXIT_SOME_FAILED
from arzsumo.resources import default_scenario
from arzsumo_studies.cli.options import add_output, add_records, add_runs, recorded_runs
from arzsumo_studies.common import RESULTS_DIR, StudyError, names_among, print_list
from arzsumo_studies.control import study as control
from arzsumo_studies.control.ablation import (
    ALL_LAWS,
    DEFAULT_STEPS,
    LAWS,
    NAME,
    PAGE,
    POWER_LAW_STEPS,
    STEPS,
    AblationOptions,
    design,
    is_step,
    run_ablation,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The ablation's options."""
    parser.add_argument("--scenario", type=Path,
                        default=default_scenario(), metavar="FILE",
                        help="the control study's base scenario (default: the shipped "
                             "default)")
    parser.add_argument("--control", type=Path, default=RESULTS_DIR / control.NAME,
                        metavar="DIR", help="the control study's --out, or its record "
                        "store: its runs of the experiment are the full configuration")
    full = parser.add_mutually_exclusive_group()
    full.add_argument("--full", type=Path, metavar="DIR",
                      help="the full configuration's runs from this --out or record store "
                           "of the control study instead (the open loop stays --control's)")
    full.add_argument("--without-full", action="store_true",
                      help="compare the steps with the open loop only")
    parser.add_argument("--experiment", choices=control.ALL_EXPERIMENTS, default="regulation",
                        help="the control study's experiment the steps change "
                             "(default: %(default)s)")
    parser.add_argument("--steps",
                        help="comma-separated steps, of " + ", ".join(STEPS)
                             + "; steps joined by + are one step with each change "
                               "(default: " + ",".join(DEFAULT_STEPS) + ", without "
                             + ",".join(POWER_LAW_STEPS) + " on a model that is not the "
                               "power law)")
    parser.add_argument("--laws", default=",".join(LAWS),
                        help="comma-separated laws ablated, of " + ", ".join(ALL_LAWS)
                             + " (default: %(default)s)")
    add_records(parser)
    add_runs(parser, seeds="1-10")
    add_output(parser, NAME, PAGE, plots=False)
    parser.add_argument("--page", default=PAGE, metavar="NAME",
                        help="the results page --docs adds the table to, DIR/NAME.md "
                             "(default: %(default)s, the default's; the control study's "
                             "--page of the same scenario)")


def options(args: argparse.Namespace) -> AblationOptions:
    """The study's options as the command line gave them."""
    steps = None if args.steps is None else tuple(
        dict.fromkeys(n.strip() for n in args.steps.split(",") if n.strip()))
    if steps is not None and (not steps or not all(is_step(s) for s in steps)):
        raise StudyError(f"--steps = {args.steps!r} is not allowed: a comma-separated list "
                         f"of {', '.join(STEPS)}, or several of them joined by +")
    laws = tuple(names_among(args.laws, list(ALL_LAWS), "--laws"))
    return AblationOptions(recorded_runs(args), scenario=args.scenario,
                           control=args.control, full=args.full,
                           without_full=args.without_full, experiment=args.experiment,
                           steps=steps,
                           laws=laws, out=args.out, docs=args.docs,
                           page=args.page)


def run(args: argparse.Namespace) -> int:
    """``--list``: the steps; otherwise run them and print the table."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    result = run_ablation(opts)
    print(result.text)
    return 0 if result.complete else EXIT_SOME_FAILED
