"""``arzsumo compare RUN_DIR... [--out DIR]``: one table across ``arzsumo run`` results;
the comparison's own directory and earlier comparisons are skipped (a glob may match them).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from arzsumo.cli.options import add_out

#: what ``arzsumo compare`` writes (a directory holding them and no summary is skipped)
OUTPUT_FILES = ("comparison.csv", "comparison.png")


def _skipped(run: Path, out: Path) -> str | None:
    """Why ``run`` is not a run to compare (None: it is one)."""
    if run.resolve() == out.resolve():
        return "the --out directory of this comparison"
    if not (run / "summary.json").exists() and any((run / f).is_file() for f in OUTPUT_FILES):
        return "the output of an earlier arzsumo compare, not a run"
    return None


def runs_to_compare(runs: list[Path], out: Path) -> list[Path]:
    """``runs`` without comparison outputs (``out`` among them), each named on stderr."""
    kept = []
    for run in runs:
        if (why := _skipped(run, out)) is None:
            kept.append(run)
        else:
            print(f"arzsumo: note: skipped {run}: {why}", file=sys.stderr)
    return kept


def cmd_compare(args: argparse.Namespace) -> int:
    from arzsumo.bridge.compare import CompareError
    from arzsumo.outputs.compare import compare_runs

    out = Path(args.out)
    runs = runs_to_compare([Path(p) for p in args.runs], out)
    if not runs:
        raise CompareError(f"runs = {' '.join(args.runs)} is not allowed: no run directory "
                           "left to compare; allowed: results directories of arzsumo run")
    table, csv, png = compare_runs(runs, out, allow_mixed=args.allow_mixed)
    print(table)
    print("written: " + ", ".join(str(p) for p in (csv, png, *sorted(out.glob("fields_*.png")))))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``compare`` to the top-level parser."""
    p = sub.add_parser("compare", help="one table across run directories (CSV and bar plot)",
                       description="Compare the summaries of several 'arzsumo run' results "
                                   "directories in one table, a CSV and a bar plot. The "
                                   "--out directory and earlier comparison outputs among "
                                   "RUN_DIR are skipped (a note says so).")
    p.add_argument("runs", nargs="+", metavar="RUN_DIR",
                   help="results directories of arzsumo run")
    add_out(p, "directory for the CSV and plot", default="results/comparison")
    p.add_argument("--allow-mixed", action="store_true",
                   help="tabulate results of different kinds (twin), scenarios, horizons or "
                        "warm-ups anyway; the table's header states the mix")
    p.set_defaults(func=cmd_compare)
