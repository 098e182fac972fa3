"""``arzsumo study sumo-options``: the command line of :mod:`arzsumo_studies.sumo_map.sumo_options`,
mapped onto its :class:`~arzsumo_studies.sumo_map.sumo_options.SumoOptionsOptions`."""

from __future__ import annotations

import argparse

from arzsumo_studies.cli.options import add_output, add_runs
from arzsumo_studies.common import names_among, print_list
from arzsumo_studies.sumo_map.sumo_options import (
    NAME,
    PAGE,
    VARIANTS,
    SumoOptionsOptions,
    design,
    run_sumo_options,
    variant_names,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    add_runs(parser, seeds="1-10")
    parser.add_argument("--no-drain", action="store_true",
                        help="end each run with the control window (faster; no "
                             "whole-demand measures)")
    parser.add_argument("--vary", default="", metavar="KEYS",
                        help="comma-separated [sumo] keys varied, of "
                             + ", ".join(f.split(".", 1)[1] for f in VARIANTS)
                             + ", or one value of a key as KEY=VALUE, e.g. "
                             "lateral_resolution_m=1.3 (default: all)")
    add_output(parser, NAME, PAGE, plots=False)


def _varied(text: str) -> tuple[str, ...]:
    """The ``--vary`` keys or ``KEY=VALUE`` variants (none given: every option)."""
    keys = [f.split(".", 1)[1] for f in VARIANTS]
    return tuple(names_among(text, keys + variant_names(), "--vary")) if text.strip() else ()


def options(args: argparse.Namespace) -> SumoOptionsOptions:
    """The study's options as the command line gave them."""
    return SumoOptionsOptions(seeds=tuple(args.seeds), drain=not args.no_drain,
                              vary=_varied(args.vary),
                              out=args.out, docs=args.docs, workers=args.workers,
                              scheduler=args.scheduler)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise run the missing variants and seeds, write the
    comparison and print it."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    result = run_sumo_options(opts, progress=not args.quiet)
    print(result.text)
    return result.code
