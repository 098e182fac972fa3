"""``arzsumo study share-models``: the command line of :mod:`arzsumo_studies.share_models`,
mapped onto its :class:`~arzsumo_studies.share_models.ShareOptions`."""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path
from typing import Any

from arzsumo.argtypes import non_negative_float, positive_int
from arzsumo.model.params import FAMILIES
from arzsumo.workflows.identify.study import JAM_FLOORS
from arzsumo_studies.cli.options import add_output, add_runs
from arzsumo_studies.common import fraction_list, print_list, seed_list
from arzsumo_studies.outputs.pages import markdown_table
from arzsumo_studies.share_models import (
    BASE,
    NAME,
    PAGE,
    ShareOptions,
    design,
    run_share_models,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    parser.add_argument("--scenario", type=Path, metavar="SCENARIO.toml",
                        help=f"the base scenario (default: the shipped {BASE})")
    parser.add_argument("--shares", type=fraction_list, default=ShareOptions.shares,
                        metavar="LIST", help="AV shares of the mainline demand (default: "
                                             "0.1,0.18,0.3,0.5)")
    parser.add_argument("--train-seeds", type=seed_list, default=seed_list("1-3"),
                        metavar="LIST", help="identification seeds (default: 1-3)")
    parser.add_argument("--validate-seeds", type=seed_list, default=seed_list("4-6"),
                        metavar="LIST", help="held-out seeds (default: 4-6)")
    parser.add_argument("--diagram", choices=FAMILIES, default="newell",
                        help="stage 1's diagram family (default: newell)")
    parser.add_argument("--jam-floor", choices=JAM_FLOORS, default="cells",
                        help="stage 1's least jam occupancy, as arzsumo identify's "
                             "(default: cells)")
    parser.add_argument("--wave-weight", type=non_negative_float, default=1.0,
                        metavar="W", help="weight of the wave-speed gap in stage 1, as "
                                          "arzsumo identify's (default: 1)")
    parser.add_argument("--set", action="append", type=sumo_assignment, default=[],
                        metavar="sumo.KEY=VALUE",
                        help="a [sumo] key set on the base scenario at every share, the "
                             "value as in TOML (e.g. sumo.time_to_teleport_s=300); "
                             "repeatable")
    parser.add_argument("--cells", type=positive_int, default=100,
                        help="kernel cells of the design (default: 100)")
    add_runs(parser, seeds=None)
    add_output(parser, NAME, PAGE, plots=False)


def sumo_assignment(text: str) -> tuple[str, Any]:
    """``sumo.KEY=VALUE`` as a (key, value) pair, the value read as TOML."""
    key, eq, value = text.partition("=")
    if not eq or not key.startswith("sumo.") or key.count(".") != 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: sumo.KEY=VALUE")
    try:
        return key, tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: the value {value!r} is not a TOML value (a number, "
            "true/false or a quoted string)") from None


def options(args: argparse.Namespace) -> ShareOptions:
    """The study's options as the command line gave them."""
    return ShareOptions(scenario=args.scenario, shares=tuple(args.shares),
                        train_seeds=tuple(args.train_seeds),
                        validate_seeds=tuple(args.validate_seeds), diagram=args.diagram,
                        jam_floor=args.jam_floor, wave_weight=args.wave_weight,
                        sumo_keys=tuple(args.set), kernel_cells=args.cells, out=args.out,
                        docs=args.docs, workers=args.workers, scheduler=args.scheduler,
                        progress=not args.quiet)


def run(args: argparse.Namespace) -> int:
    """``--list``: the runs; otherwise map, identify and design every share; print the
    table and the scenarios written."""
    opts = options(args)
    if args.list:
        return print_list(design(opts))
    result = run_share_models(opts)
    print(markdown_table(result.table))
    for m in result.models:
        print(f"{m.point}: {m.scenario}")
    return 0
