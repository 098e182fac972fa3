"""Helpers shared by the CLI modules (``cli.py`` and ``cli_*.py`` import them from here, so
no CLI module imports another's commands)."""

from __future__ import annotations

import argparse

from arzsumo.model.params import PRESETS
from arzsumo.scenario import Scenario, load_scenario, scenario_from_preset


def scenario_of(args: argparse.Namespace) -> Scenario:
    """The scenario named by ``--scenario FILE.toml``, else the ``--preset``."""
    if getattr(args, "scenario", None):
        return load_scenario(args.scenario)
    return scenario_from_preset(args.preset)


def add_model_source(p: argparse.ArgumentParser) -> None:
    """Add the exclusive ``--preset`` | ``--scenario`` options to ``p``."""
    src = p.add_mutually_exclusive_group()
    src.add_argument("--preset", default="paper_base",
                     help=f"named model preset ({', '.join(sorted(PRESETS))})")
    src.add_argument("--scenario", metavar="FILE.toml", help="scenario file instead of a preset")
