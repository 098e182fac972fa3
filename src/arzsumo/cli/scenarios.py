"""Scenario and sweep arguments of the CLI: a file or a shipped name
(:func:`arzsumo.api.scenarios.scenario_file`; ``arzsumo list`` shows the names)."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.api.scenarios import load_scenario, scenario_file, sweep_file
from arzsumo.scenario import Scenario, scenario_from_preset


def load_named(text: str | None, default: Path | None = None) -> tuple[Path, Scenario]:
    """(file, validated scenario) of a scenario argument (:func:`scenario_file`)."""
    path = scenario_file(text, default)
    return path, load_scenario(path)


def scenario_of(args: argparse.Namespace) -> Scenario:
    """The scenario of ``--scenario FILE|NAME``, else of the ``--preset``; one with a
    ``[network]`` takes the section's length and width from that network (checked)."""
    if getattr(args, "scenario", None):
        from arzsumo.bridge.road import with_network

        return with_network(load_named(args.scenario)[1])
    return scenario_from_preset(args.preset)


__all__ = ["load_named", "scenario_file", "scenario_of", "sweep_file"]
