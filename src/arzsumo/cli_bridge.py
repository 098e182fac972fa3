"""CLI commands of the closed loop: ``arzsumo run`` and ``arzsumo compare``."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

from arzsumo.cli_args import non_negative_float, positive_float, seed_int
from arzsumo.control.registry import controller_names

log = logging.getLogger("arzsumo")


def cmd_run(args: argparse.Namespace) -> int:
    from arzsumo.bridge.session import default_run_name, prepare_run, run_in_sumo
    from arzsumo.outdir import OutputDir
    from arzsumo.outputs.bridge import write_results
    from arzsumo.resources import default_scenario
    from arzsumo.scenario import load_scenario
    from arzsumo.sumo.frontend import Frontend

    # the shipped default, found in the package so that any working directory will do
    path = Path(args.scenario) if args.scenario else default_scenario()
    sc = load_scenario(path)
    fcd = True if args.fcd else None   # without --fcd the scenario's [sumo] fcd holds
    prepared = prepare_run(sc, controller=args.controller, seed=args.seed,
                           horizon=args.horizon, warmup=args.warmup, fcd=fcd)
    frontend = "gui" if args.gui else "libsumo"
    Frontend(frontend).check()   # no display or no sumo-gui: one line, before any output
    if args.dry_run:
        print(prepared.describe())
        return 0
    out = Path(args.out) if args.out else Path("results") / default_run_name(
        sc, prepared.settings, prepared.sumo)
    # the output is checked and claimed before SUMO starts; Ctrl-C or an error removes it
    with OutputDir(out, "run", overwrite=args.overwrite) as target:
        session = run_in_sumo(sc, controller=args.controller, seed=args.seed,
                              horizon=args.horizon, warmup=args.warmup, fcd=fcd,
                              progress=not args.quiet, frontend=frontend)
        text = path.read_text(encoding="utf-8") + session.resolved_comment()
        _, summ = write_results(session.result, target, text, plots=not args.no_plots)
    if args.json:
        from arzsumo.io import json_safe

        print(json.dumps(json_safe(summ), indent=2))
    else:
        from arzsumo.bridge.compare import summary_table

        print(summary_table([summ]))
        print(f"results: {out}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from arzsumo.outputs.compare import compare_runs

    table, csv, png = compare_runs([Path(p) for p in args.runs], Path(args.out),
                                   allow_mixed=args.allow_mixed)
    print(table)
    print(f"written: {csv}, {png}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``run`` and ``compare`` to the top-level parser."""
    p = sub.add_parser("run", help="closed loop in SUMO with the PDE twin alongside",
                       description="Run a scenario's closed loop in SUMO: warm-up under the "
                                   "nominal meter, then the [run] controller on the ramp "
                                   "meter, with the PDE twins alongside; write the results.")
    p.add_argument("scenario", nargs="?", metavar="SCENARIO.toml",
                   help="scenario file (default: the shipped scenarios/default.toml)")
    p.add_argument("--out", metavar="DIR",
                   help="results directory (default results/NAME-CONTROLLER-seedN-hTs)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a previous run result in the --out directory")
    p.add_argument("--seed", type=seed_int,
                   help="SUMO seed in [0, 2^31) (default: [sumo] seed)")
    p.add_argument("--controller", choices=list(controller_names("sumo")),
                   help="controller (default: [run] controller)")
    p.add_argument("--horizon", type=positive_float,
                   help="control horizon after the warm-up, s; at least one control period "
                        "(default: [sumo] horizon_s)")
    p.add_argument("--warmup", type=non_negative_float,
                   help="warm-up under the nominal meter before control, s (default: [run] "
                        "warmup_s; the name of the default --out then ends in -wWs)")
    p.add_argument("--dry-run", action="store_true",
                   help="check the scenario and the options as the run would, print what "
                        "it would do, and exit without starting SUMO")
    p.add_argument("--fcd", action="store_true",
                   help="keep SUMO's trajectories of every vehicle every step in "
                        "fcd.xml.gz (as [sumo] fcd = true)")
    p.add_argument("--gui", action="store_true",
                   help="watch the run in sumo-gui (driven through TraCI; slower; needs a "
                        "display)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("compare", help="one table across run directories (CSV and bar plot)",
                       description="Compare the summaries of several 'arzsumo run' results "
                                   "directories in one table, a CSV and a bar plot.")
    p.add_argument("runs", nargs="+", metavar="RUN_DIR",
                   help="results directories of arzsumo run")
    p.add_argument("--out", metavar="DIR", default="comparison",
                   help="directory for the CSV and plot")
    p.add_argument("--allow-mixed", action="store_true",
                   help="tabulate results of different kinds (twin), scenarios, horizons or "
                        "warm-ups anyway; the table's header states the mix")
    p.set_defaults(func=cmd_compare)
