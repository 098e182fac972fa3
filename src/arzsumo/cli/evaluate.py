"""``arzsumo evaluate SCENARIO --controllers LIST --seeds N``: controllers on the same seeds
in SUMO, compared with the open loop seed by seed (:func:`arzsumo.evaluate`)."""

from __future__ import annotations

import argparse
import shlex
import sys

from arzsumo.argtypes import positive_float, positive_int, seed_int
from arzsumo.cli.options import (
    add_no_plots,
    add_out,
    add_overwrite,
    add_parallel,
    add_quiet,
    add_scenario,
    add_warmup,
)
from arzsumo.control.registry import default_controllers
from arzsumo.errors import EXIT_SOME_FAILED

#: the measures printed, in the report's order: whole-demand time spent, the ramp's
#: 95th-percentile wait, the network's time loss over the window
HEADLINES = ("network_whole_demand.time_spent_s.total", "network_whole_demand.ramp_wait_s.p95",
             "network.time_loss_s.total")


def cmd_evaluate(args: argparse.Namespace) -> int:
    from arzsumo.api.evaluation import evaluate, seed_list
    from arzsumo.api.scenarios import scenario_file
    from arzsumo.bridge.session import CLI_NAMES
    from arzsumo.sweep.evaluate import BASELINE

    scenario = scenario_file(args.scenario)
    command = "arzsumo " + " ".join(shlex.quote(a) for a in sys.argv[1:]) \
        if sys.argv[1:2] == ["evaluate"] else ""
    res = evaluate(scenario, controllers=args.controllers,   # "open,etc": split there
                   seeds=seed_list(args.seeds, args.seed_start), out=args.out,
                   horizon_s=args.horizon, warmup_s=args.warmup,
                   allow_short_warmup=args.allow_short_warmup, workers=args.workers,
                   scheduler=args.scheduler, share_warmup=not args.no_shared_warmup,
                   overwrite=args.overwrite, progress=not args.quiet,
                   plots=not args.no_plots, baseline_from=args.baseline_from,
                   runs_from=args.runs_from or (), command=command,
                   option_names=CLI_NAMES)
    rep, bad = res.sweep, None
    if rep is None:
        print(f"evaluate {scenario.name}: every run taken from --runs-from, none executed")
    else:
        print(f"evaluate {scenario.name}: {rep.total} runs, {rep.skipped} already finished, "
              f"{rep.executed} executed on {rep.backend} in {rep.wall_time:.1f} s")
        bad = rep.table[~rep.table["status"].isin(["ok"])] if rep.table is not None else None
    if bad is not None:
        for _, row in bad.iterrows():
            print(f"  {row['run_id']}: {row['status']}: {str(row['error']).splitlines()[0]}")
    main = res.table[res.table["measure"].isin(HEADLINES)]
    for r in main.itertuples(index=False):
        if r.controller != BASELINE:
            print(f"  {r.label} ({r.unit}), {r.controller} minus {BASELINE}: "
                  f"{r.diff_mean:.3g} [{r.diff_ci_low:.3g}, {r.diff_ci_high:.3g}]")
    print("  report: " + ", ".join(str(p) for p in res.files))
    return 0 if bad is None or bad.empty else EXIT_SOME_FAILED


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``evaluate`` to the top-level parser."""
    p = sub.add_parser("evaluate", help="controllers on the same seeds, paired against the "
                                        "open loop (CSV, Markdown, figure)",
                       description="Run every controller on the same SUMO seeds through the "
                                   "sweep engine (parallel, resumable, Dask-capable) and "
                                   "report per measure the mean with its 95 % CI and the "
                                   "paired difference against the open loop with its 95 % "
                                   "CI, wins and losses.")
    add_scenario(p)
    p.add_argument("--controllers",
                   default=",".join(default_controllers()),
                   help="comma-separated controllers; open (the baseline) is added first "
                        "when missing")
    p.add_argument("--seeds", type=positive_int, default=20,
                   help="number of seeds N (20: a headline needs 20 paired seeds)")
    p.add_argument("--seed-start", type=seed_int, default=1,
                   help="first seed S: the seeds are S, S+1, ..., S+N-1")
    p.add_argument("--horizon", type=positive_float,
                   help="control horizon after the warm-up, s (default: [sumo] horizon_s)")
    add_warmup(p, "warm-up under the nominal meter before control, s; at least the "
                  "scenario's fill phase (default: [run] warmup_s)")
    add_parallel(p)
    add_out(p, "output directory (default results/evaluate/<scenario file name>); a "
               "restart with the same directory runs only what is missing")
    add_overwrite(p, "evaluation", "discard the runs and report of a previous evaluation "
                                   "in --out and run everything again")
    p.add_argument("--baseline-from", metavar="DIR",
                   help="take the open-loop runs from the earlier evaluation in DIR instead "
                        "of running them (same seeds, horizon and warm-up; its scenario may "
                        "differ only in what does not act on an open loop: [estimation], "
                        "[sensing], [actuation], [design], [run] controller)")
    p.add_argument("--runs-from", metavar="DIR", action="append",
                   help="an earlier evaluation or sweep (repeatable): a controller whose "
                        "runs on all the seeds are there, the same SUMO runs (scenarios "
                        "that differ only in what that controller does not read), is taken "
                        "from there instead of run")
    add_quiet(p)
    add_no_plots(p, "skip the figure")
    p.set_defaults(func=cmd_evaluate)
