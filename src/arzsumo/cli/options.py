"""The options several ``arzsumo`` commands share, each declared once here, so that a flag
means the same and is checked the same in every command (the studies' own:
:mod:`arzsumo_studies.common`)."""

from __future__ import annotations

import argparse

from arzsumo.argtypes import non_negative_float, positive_int, seed_int, seed_list
from arzsumo.model.params import PRESETS


def add_out(p: argparse.ArgumentParser, help: str, *, default: str | None = None,
            required: bool = False) -> None:
    """``--out DIR``: where the command writes (``help`` says what, and its default)."""
    p.add_argument("--out", metavar="DIR", default=default, required=required, help=help)


def add_overwrite(p: argparse.ArgumentParser, kind: str, help: str | None = None) -> None:
    """``--overwrite``: replace a previous result of ``kind`` (``run``, ``twin``...)."""
    p.add_argument("--overwrite", action="store_true",
                   help=help or f"replace a previous {kind} result in the --out directory")


def add_workers(p: argparse.ArgumentParser, help: str | None = None,
                default: int | None = None) -> None:
    """``--workers N``: local processes, an integer >= 1."""
    p.add_argument("--workers", type=positive_int, default=default,
                   help=help or "local processes (default: one per core); ignored with "
                                "--scheduler")


def add_parallel(p: argparse.ArgumentParser) -> None:
    """The sweep engine's ``--workers N``, ``--scheduler ADDRESS``, ``--no-shared-warmup``."""
    add_workers(p)
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler address, e.g. tcp://SCHEDULER-HOST:8786")
    p.add_argument("--no-shared-warmup", action="store_true",
                   help="give every SUMO run its own warm-up (by default the runs of a "
                        "seed that differ only in the controller simulate it once; the "
                        "results are the same to the last bit)")


def add_quiet(p: argparse.ArgumentParser) -> None:
    """``--quiet``: no progress bar."""
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def add_no_plots(p: argparse.ArgumentParser, help: str = "skip the PNG figures") -> None:
    """``--no-plots``: write no figures."""
    p.add_argument("--no-plots", action="store_true", help=help)


def add_json(p: argparse.ArgumentParser, help: str = "print JSON") -> None:
    """``--json``: print machine-readable output instead of text."""
    p.add_argument("--json", action="store_true", help=help)


def add_seed(p: argparse.ArgumentParser, default_from: str) -> None:
    """``--seed N``: one SUMO seed in [0, 2^31); ``default_from`` names the default."""
    p.add_argument("--seed", type=seed_int,
                   help=f"SUMO seed in [0, 2^31) (default: {default_from})")


def add_seeds(p: argparse.ArgumentParser, help: str, *, flag: str = "--seeds",
              required: bool = False) -> None:
    """``--seeds SEEDS``: comma-separated seeds, ``A-B`` for a range (``1,2,5-8``)."""
    p.add_argument(flag, type=seed_list, metavar="SEEDS", required=required,
                   help=f"{help}, comma-separated, A-B for a range")


def add_scenario(p: argparse.ArgumentParser, help: str = "scenario file", *,
                 optional: bool = False) -> None:
    """The positional ``SCENARIO``: a TOML file or a shipped scenario name."""
    text = f"{help}, or a shipped scenario name ('arzsumo list')"
    if optional:
        p.add_argument("scenario", nargs="?", metavar="SCENARIO",
                       help=f"{text} (default: the shipped default)")
    else:
        p.add_argument("scenario", metavar="SCENARIO", help=text)


def add_model_source(p: argparse.ArgumentParser, *, preset_help: str = "named model preset",
                     scenario_help: str = "scenario file instead of a preset") -> None:
    """The exclusive ``--preset NAME`` | ``--scenario FILE|NAME`` (read by ``scenario_of``)."""
    src = p.add_mutually_exclusive_group()
    src.add_argument("--preset", default="paper_base",
                     help=f"{preset_help} ({', '.join(sorted(PRESETS))})")
    src.add_argument("--scenario", metavar="FILE.toml",
                     help=f"{scenario_help} (or a shipped scenario name)")


def add_warmup(p: argparse.ArgumentParser, help: str) -> None:
    """``--warmup S`` (>= 0 s) and ``--allow-short-warmup`` (checked by ``check_warmup``)."""
    p.add_argument("--warmup", type=non_negative_float, help=help)
    p.add_argument("--allow-short-warmup", action="store_true",
                   help="start control before the scenario's fill phase ([sumo] fill_s) "
                        "has ended (refused otherwise: the measures would describe the "
                        "fill)")
