"""``arzsumo reproduce [--out DIR] [--quick]``: every experiment of the paper's section 5
(:func:`arzsumo.workflows.paper.reproduce.reproduce`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from arzsumo.cli.options import add_no_plots, add_out, add_overwrite, add_workers
from arzsumo.errors import EXIT_INCOMPLETE


def cmd_reproduce(args: argparse.Namespace) -> int:
    from arzsumo.outdir import OutputDir
    from arzsumo.resources import shipped_scenarios_dir
    from arzsumo.workflows.paper.compare import REPRODUCED, claims
    from arzsumo.workflows.paper.report import write_reproduction
    from arzsumo.workflows.paper.reproduce import reproduce

    out = Path(args.out) if args.out else Path("results") / "reproduce"
    with OutputDir(out, "reproduce", overwrite=args.overwrite) as target:
        paper = args.scenarios or shipped_scenarios_dir() / "paper"
        rep = reproduce(paper, quick=args.quick, only=args.only or None,
                        workers=args.workers,
                        twin={"scheme": args.scheme} if args.scheme else None)
        write_reproduction(rep, target, plots=not args.no_plots)
    cl = claims(rep)
    smoke = ("quick: a smoke test on a coarse grid and a short horizon; the verdicts say "
             "the code runs, not what the paper's experiments give")
    print(f"reproduce: {len(rep.records)} runs, {rep.open_loops} open loops, "
          f"{rep.wall_time:.1f} s" + (f" ({smoke})" if rep.quick else ""))
    for c in cl:
        mark = "yes" if c.verdict == REPRODUCED else "NO "
        print(f"  [{'smoke ' if rep.quick else ''}{mark}] {c.claim}: {c.ours}")
    print(f"  {sum(c.verdict == REPRODUCED for c in cl)} of {len(cl)} claims reproduced in "
          f"direction{' in the smoke test' if rep.quick else ''}; report in {out}/report.md")
    incomplete = [r.name for r in rep.records if not r.summary["complete"]]
    if incomplete:
        print(f"  incomplete runs: {', '.join(incomplete)}")
    return 0 if not incomplete else EXIT_INCOMPLETE


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``reproduce`` to the top-level parser."""
    r = sub.add_parser("reproduce",
                       help="run every experiment of section 5 and compare with the paper",
                       description="Run every section 5 experiment of the paper in the "
                                   "PDE twin, compare each claim with the paper's, and "
                                   "write a report.")
    add_out(r, "output directory (default results/reproduce)")
    add_overwrite(r, "reproduce")
    r.add_argument("--quick", action="store_true",
                   help="tiny grid and horizon: a smoke test, numbers not meaningful")
    r.add_argument("--scenarios", metavar="DIR", default=None,
                   help="directory of the section 5 scenario files (default: the shipped "
                        "paper/ scenarios)")
    r.add_argument("--only", metavar="NAME", nargs="*",
                   help="run only these scenario names")
    r.add_argument("--scheme", choices=("first", "muscl"),
                   help="override every scenario's [twin] scheme (files: first order)")
    add_workers(r, "processes, an integer >= 1 (results do not depend on it)", default=1)
    add_no_plots(r)
    r.set_defaults(func=cmd_reproduce)
