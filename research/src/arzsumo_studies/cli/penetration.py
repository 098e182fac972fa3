"""``arzsumo study penetration``: the command line of :mod:`arzsumo_studies.control.penetration`,
mapped onto its :class:`~arzsumo_studies.control.penetration.PenetrationOptions`."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.argtypes import seed_list
from arzsumo.errors import EXIT_SOME_FAILED
from arzsumo_studies.cli.options import add_output, add_records, add_runs, plots_wanted
from arzsumo_studies.common import print_list
from arzsumo_studies.control.penetration import (
    NAME,
    PAGE,
    PenetrationOptions,
    design,
    run_penetration,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The penetration study's options (the shares are the sweep files')."""
    parser.add_argument("--seeds", type=seed_list, metavar="LIST",
                        help="SUMO seeds, e.g. 1-10 (default: each sweep file's own)")
    parser.add_argument("--share-models", type=Path, metavar="DIR",
                        help="run the ETC on each share's own scenario from arzsumo study "
                             "share-models (its --out) instead of the shipped sweeps")
    parser.add_argument("--with-open", action="store_true",
                        help="with --share-models, the open loop too on the same seeds "
                             "(sharing each seed's warm-up): the ETC's paired effect per "
                             "share, and whether the stream's waves still grow there")
    add_records(parser)
    add_runs(parser, seeds=None)
    add_output(parser, NAME, PAGE)
    parser.add_argument("--page", default=PAGE,
                        help=f"the page's name under --docs (default: {PAGE})")


def options(args: argparse.Namespace) -> PenetrationOptions:
    """The study's options as the command line gave them."""
    return PenetrationOptions(
        seeds=None if args.seeds is None else tuple(args.seeds), records=args.records,
        report=args.report, share_models=args.share_models, with_open=args.with_open,
        out=args.out, docs=args.docs, page=args.page,
        plots=plots_wanted(args), workers=args.workers, scheduler=args.scheduler,
        progress=not args.quiet)


def run(args: argparse.Namespace) -> int:
    """``--list``: the sweeps; otherwise run them and print the page."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    result = run_penetration(opts)
    print(result.text)
    return 0 if result.complete else EXIT_SOME_FAILED
