"""``arzsumo network``: the section a scenario runs on and the detectors placed on it."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.cli.options import add_scenario
from arzsumo.errors import ArzsumoError


def png_path(text: str) -> Path:
    """``--figure``: a file name ending in .png."""
    if not text.lower().endswith(".png"):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: a file name ending in "
                                         ".png")
    return Path(text)


def cmd_network(args: argparse.Namespace) -> int:
    from arzsumo.api.network import road_geometry
    from arzsumo.api.scenarios import load_scenario

    sc = load_scenario(args.scenario)
    road = road_geometry(sc)
    where = "its [network]" if sc.network is not None else "the shipped network"
    print(f"scenario {sc.name} ({sc.source}) on {where}")
    for line in road.placements():
        print(f"  {line}")
    if args.figure is not None:
        from arzsumo.outputs.network import write_network_figure

        try:
            path = write_network_figure(road, args.figure, f"{sc.name}: the section and "
                                                            "its detectors")
        except OSError as exc:
            raise ArzsumoError(f"--figure {args.figure} could not be written: {exc}") from None
        print(f"figure: {path}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``arzsumo network`` to the CLI's subparsers."""
    p = sub.add_parser(
        "network", help="check a scenario's network and show (draw) its detectors",
        description="Check the scenario's [network] table as 'arzsumo run --dry-run' does, "
                    "print where the loop stations, ALINEA's loop, the meter and the cells "
                    "sit, and draw them with --figure (docs/networks.md).")
    add_scenario(p, optional=True)
    p.add_argument("--figure", type=png_path, metavar="FILE.png",
                   help="draw the section and its detectors into this PNG")
    p.set_defaults(func=cmd_network)
