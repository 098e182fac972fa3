"""CLI commands of the closed loop: ``arzsumo run`` and ``arzsumo compare``."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

log = logging.getLogger("arzsumo")


def cmd_run(args: argparse.Namespace) -> int:
    from arzsumo.bridge.outputs import write_results
    from arzsumo.bridge.session import run_in_sumo
    from arzsumo.resources import default_scenario
    from arzsumo.scenarios import load_scenario

    # the shipped default, found in the package so that any working directory will do
    path = Path(args.scenario) if args.scenario else default_scenario()
    sc = load_scenario(path)
    session = run_in_sumo(sc, controller=args.controller, seed=args.seed,
                          horizon=args.horizon, progress=not args.quiet)
    out = Path(args.out) if args.out else Path("results") / (
        f"{sc.name}-{session.settings.controller}-seed{session.sumo.seed}")
    text = path.read_text(encoding="utf-8") + session.resolved_comment()
    out, summ = write_results(session.result, out, text, plots=not args.no_plots)
    if args.json:
        from arzsumo.twin.output import json_safe

        print(json.dumps(json_safe(summ), indent=2))
    else:
        from arzsumo.bridge.compare import summary_table

        print(summary_table([summ]))
        print(f"results: {out}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from arzsumo.bridge.compare import compare_runs

    table, csv, png = compare_runs([Path(p) for p in args.runs], Path(args.out))
    print(table)
    print(f"written: {csv}, {png}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``run`` and ``compare`` to the top-level parser."""
    p = sub.add_parser("run", help="closed loop in SUMO with the PDE twin alongside")
    p.add_argument("scenario", nargs="?", help="scenario file (default: the shipped "
                   "scenarios/default.toml)")
    p.add_argument("--out", help="results directory (default results/NAME-CONTROLLER-seedN)")
    p.add_argument("--seed", type=int, help="SUMO seed (overrides [sumo] seed)")
    p.add_argument("--controller", choices=["open", "backstepping", "etc", "observer-etc",
                                            "alinea"], help="override [run] controller")
    p.add_argument("--horizon", type=float, help="control horizon, s (overrides [sumo])")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("compare", help="one table across run directories (CSV and bar plot)")
    p.add_argument("runs", nargs="+", help="results directories of arzsumo run")
    p.add_argument("--out", default="comparison", help="directory for the CSV and plot")
    p.set_defaults(func=cmd_compare)
