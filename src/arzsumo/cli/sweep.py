"""``arzsumo sweep SWEEP.toml [--workers N] [--scheduler ADDRESS] [--out DIR]``
(:func:`arzsumo.sweep.run_sweep`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.cli.options import add_no_plots, add_out, add_parallel, add_quiet
from arzsumo.cli.scenarios import sweep_file
from arzsumo.errors import EXIT_SOME_FAILED


def cmd_sweep(args: argparse.Namespace) -> int:
    from arzsumo.sweep import load_sweep, run_sweep
    from arzsumo.sweep.worker import FINISHED
    from arzsumo.workflows.paper.values import paper_points

    spec = load_sweep(sweep_file(args.sweep))
    if args.list:
        for run in spec.runs():
            print(run.run_id)
        return 0
    out = Path(args.out) if args.out else Path("results") / "sweeps" / spec.name
    rep = run_sweep(spec, out, workers=args.workers, scheduler=args.scheduler,
                    share_warmup=not args.no_shared_warmup,
                    progress=not args.quiet, plots=not args.no_plots,
                    paper=paper_points(spec.paper))
    df = rep.table
    bad = df[~df["status"].isin(FINISHED)]
    print(f"sweep {spec.name} ({spec.engine}): {rep.total} runs, {rep.skipped} already "
          f"finished, {rep.executed} executed on {rep.backend} in {rep.wall_time:.1f} s")
    print("  status: " + ", ".join(f"{k} {v}" for k, v in
                                   df["status"].value_counts().sort_index().items()))
    for _, row in bad.iterrows():
        print(f"  {row['run_id']}: {row['status']}: {str(row['error']).splitlines()[0]}")
    print(f"  table: {out / 'summaries.parquet'}")
    return 0 if bad.empty else EXIT_SOME_FAILED


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``sweep`` to the top-level parser."""
    p = sub.add_parser("sweep", help="run a sweep file on a process pool or a Dask cluster",
                       description="Expand a sweep file (a base scenario, an engine, axes and "
                                   "seeds) into runs, run what is not finished yet, and write "
                                   "one table and plots. 'arzsumo list' shows the shipped "
                                   "sweep files.")
    p.add_argument("sweep", metavar="SWEEP",
                   help="sweep file (base, engine, axes), or a shipped sweep name "
                        "('arzsumo list')")
    add_parallel(p)
    add_out(p, "output directory (default results/sweeps/<name>); a restart with the same "
               "directory runs only what is missing")
    p.add_argument("--list", action="store_true", help="print the run IDs and exit")
    add_quiet(p)
    add_no_plots(p)
    p.set_defaults(func=cmd_sweep)
