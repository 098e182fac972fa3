"""``run_study``: a study run as ``arzsumo study NAME ARGS...`` would run it, without the CLI."""

from __future__ import annotations

import argparse

import pytest
from arzsumo_studies.cli.catalog import STUDIES


def parse(name: str, *argv: str) -> argparse.Namespace:
    """The namespace ``arzsumo study NAME ARGV`` would give the study."""
    parser = argparse.ArgumentParser(prog=f"arzsumo study {name}")
    STUDIES[name].add_arguments(parser)
    return parser.parse_args([str(a) for a in argv])


@pytest.fixture
def run_study():
    """``run_study(name, *argv) -> exit code``."""
    def run(name: str, *argv: str) -> int:
        return STUDIES[name].run(parse(name, *argv))

    return run
