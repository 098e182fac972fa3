"""The command-line options the studies share, and their mapping onto the studies' own
options (:class:`~arzsumo_studies.recorded.RecordedRuns`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.argtypes import positive_float, positive_int, seed_list
from arzsumo_studies.common import DOCS_DIR, RESULTS_DIR
from arzsumo_studies.recorded import RecordedRuns


def add_output(parser: argparse.ArgumentParser, name: str, page: str,
               plots: bool = True) -> None:
    """``--out`` (default ``results/studies/NAME``), ``--docs`` (the results page
    ``page``) and, with ``plots``, ``--no-plots``."""
    parser.add_argument("--out", type=Path, default=RESULTS_DIR / name, metavar="DIR",
                        help="where the tables, figures and runs go; a later call with "
                             "the same directory runs only what is missing")
    parser.add_argument("--docs", type=Path, nargs="?", const=DOCS_DIR, metavar="DIR",
                        help=f"also regenerate this study's block of the results page "
                             f"DIR/{page}.md, its files in DIR/{page}/ (DIR: {DOCS_DIR})")
    if plots:
        parser.add_argument("--no-plots", action="store_true", help="skip the figures")


def add_study_scenario(parser: argparse.ArgumentParser, verb: str = "recorded") -> None:
    """``--scenario``: the scenario file the study's runs are ``verb`` on (default: the
    former default, lateral_files)."""
    parser.add_argument("--scenario", type=Path, metavar="SCENARIO.toml",
                        help=f"scenario {verb} (default: the former default, lateral_files)")


def add_scenario_times(parser: argparse.ArgumentParser) -> None:
    """``--warmup`` and ``--horizon`` (control horizon), s (default: the scenario's)."""
    parser.add_argument("--warmup", type=positive_float, help="s (default: the scenario's)")
    parser.add_argument("--horizon", type=positive_float,
                        help="control horizon, s (default: the scenario's)")


def add_measured_window(parser: argparse.ArgumentParser, warmup_s: float) -> None:
    """``--warmup`` (default ``warmup_s``) s not measured, then ``--measured`` s measured,
    at the SUMO step ``--step``, s (an open-loop SUMO map's window)."""
    parser.add_argument("--warmup", type=positive_float, default=warmup_s,
                        help="s not measured")
    parser.add_argument("--measured", type=positive_float, default=450.0, help="s measured")
    parser.add_argument("--step", type=positive_float, default=0.1, help="SUMO step, s")


def add_runs(parser: argparse.ArgumentParser, seeds: str | None) -> None:
    """``--seeds`` (default ``seeds``; none when None), ``--workers``, ``--scheduler``,
    ``--quiet``, ``--list``."""
    if seeds is not None:
        parser.add_argument("--seeds", type=seed_list, default=seed_list(seeds),
                            metavar="LIST", help=f"SUMO seeds, e.g. 1-10 or 1,2,3 "
                                                 f"(default: {seeds})")
    parser.add_argument("--workers", type=positive_int, metavar="N",
                        help="local processes (default: one per core); ignored with "
                             "--scheduler")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on this Dask scheduler, e.g. tcp://HOST:8786")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--list", action="store_true",
                        help="print the runs of the design and exit")


def plots_wanted(args: argparse.Namespace) -> bool:
    """Whether the study draws its figures (``--no-plots`` not given)."""
    return not getattr(args, "no_plots", False)


def add_records(parser: argparse.ArgumentParser) -> None:
    """``--report`` and ``--records``."""
    parser.add_argument("--report", action="store_true",
                        help="run nothing: the tables from the runs already there "
                             "(finished so far, while a study is running too)")
    parser.add_argument("--records", type=Path, metavar="DIR",
                        help="a store of run records (a table per experiment, "
                             "DIR/<experiment>/records.jsonl, a line per finished run): "
                             "the runs it holds are not run again, and every finished run "
                             "is added to it; kept under version control, it carries the "
                             "study across machines")


def recorded_runs(args: argparse.Namespace, seeds: list[int] | None = None) -> RecordedRuns:
    """The :class:`RecordedRuns` of ``--seeds`` (or ``seeds``), ``--records``,
    ``--report``, ``--runs-from``, ``--workers``, ``--scheduler`` and ``--quiet``."""
    return RecordedRuns(tuple(args.seeds if seeds is None else seeds), args.records,
                        args.report, tuple(getattr(args, "runs_from", None) or ()),
                        args.workers, args.scheduler, not args.quiet)
