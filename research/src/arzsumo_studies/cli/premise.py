"""``arzsumo premise SCENARIO [--seeds N] [--seed-start S] [--out DIR] [--json]``: is the
scenario the stream the paper models?

Per seed a baseline, a paired pulse and a release-rate staircase in SUMO, open loop
(:mod:`arzsumo_studies.premise.runs`) sharing one warm-up, one task per seed on the sweep
engine's local pool or a Dask cluster, resumable in ``OUT/runs``; then every premise gate
per seed and the verdict over seeds (:mod:`arzsumo_studies.premise.study`, research/premise.md); a
table on stdout (or ``--json``) and ``premise.json``, ``premise.csv``, ``premise.png`` in ``--out``.
Exit codes: 0 the premise holds (every premise gate passes on most seeds; the model's
gates are reported apart and do not decide), 5 it does not, 2 a user error.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from arzsumo.argtypes import SEED_LIMIT, positive_float, positive_int, seed_int
from arzsumo.cli.options import (
    add_json,
    add_no_plots,
    add_out,
    add_parallel,
    add_quiet,
    add_scenario,
    add_warmup,
)
from arzsumo.cli.scenarios import load_named
from arzsumo.errors import EXIT_PREMISE_FAILS, ScenarioError
from arzsumo.units import veh_h_to_veh_s

#: the pulse floors of :data:`arzsumo_studies.premise.floors.FLOORS` (kept here: no import of
#: the studies when the parser is built)
FLOORS = ("auto", "seeds", "late", "none")


def cmd_premise(args: argparse.Namespace) -> int:
    from arzsumo.bridge.session import meter_curve_of
    from arzsumo.io import dump_toml
    from arzsumo.outdir import resumable_dir
    from arzsumo_studies.outputs.premise import premise_table, theory_lines, write_premise
    from arzsumo_studies.premise.runs import PremiseOptions, check_options
    from arzsumo_studies.premise.study import (
        AnalysisOptions,
        check_window,
        default_window,
        model_speeds,
        report_document,
        run_premise,
    )

    path, sc = load_named(args.scenario)
    from arzsumo.bridge.session import check_warmup  # SUMO's side: not at --help

    check_warmup(sc, args.warmup, args.window, args.allow_short_warmup)
    if args.seed_start + args.seeds > SEED_LIMIT:
        raise ScenarioError(f"--seed-start = {args.seed_start} is not allowed with --seeds = "
                            f"{args.seeds}: the last seed must be below 2^31")
    warmup = sc.run.warmup if args.warmup is None else float(args.warmup)
    trip = args.round_trip or model_speeds(sc).round_trip
    window = args.window or default_window(sc, trip)
    check_window(window, trip, args.round_trip is not None)
    opts = PremiseOptions(window, args.pulse_s, args.level_s, args.levels,
                          veh_h_to_veh_s(args.step_veh_h))
    check_options(sc, opts, meter_curve_of(sc.sumo, sc.source))
    analysis = AnalysisOptions(args.round_trip, args.smooth_s, args.floor)
    seeds = list(range(args.seed_start, args.seed_start + args.seeds))
    out = Path(args.out) if args.out else Path("results") / "premise" / path.stem
    with resumable_dir(out, "premise") as target:
        report = run_premise(path, sc, seeds, warmup, opts, analysis, target,
                             workers=args.workers, scheduler=args.scheduler,
                             progress=not args.quiet)
        doc = report_document(report, sc, path, dump_toml(sc.tables), warmup, opts,
                              analysis)
        files = write_premise(target, doc, report.gates, report.pulse_series,
                              report.staircases, plots=not args.no_plots)
    if args.json:
        from arzsumo.io import json_safe

        print(json.dumps(json_safe(doc), indent=2))
    else:
        print(f"premise {sc.name}: seeds {seeds[0]}-{seeds[-1]}, window {window:g} s, "
              f"round trip T = {report.round_trip:.4g} s, pulse floor: "
              f"{report.floor_method}")
        print(premise_table(report.gates, report.verdict, report.pooled_actuator,
                            report.pooled_pulse))
        if report.theory:
            print(theory_lines(report.theory))
        print("  report: " + ", ".join(str(p) for p in files))
    return 0 if report.verdict.passed else EXIT_PREMISE_FAILS


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``premise`` to the top-level parser."""
    p = sub.add_parser("premise", help="is the scenario the stream the paper models? open-loop "
                                       "premise gates over seeds (research/premise.md)",
                       description="Run the premise gates on a scenario in SUMO, open loop: "
                                   "per seed a baseline, a paired pulse and a release-rate "
                                   "staircase; every gate per seed and the verdict over "
                                   "seeds. Exit code 0: the premise holds; 5: it does not.")
    add_scenario(p)
    p.add_argument("--seeds", type=positive_int, default=5,
                   help="number of seeds N (the verdict asks for most seeds: 4 of 5)")
    p.add_argument("--seed-start", type=seed_int, default=1,
                   help="first seed S: the seeds are S, S+1, ..., S+N-1")
    add_warmup(p, "warm-up under the nominal meter before each window, s; at least the "
                  "scenario's fill phase (default: [run] warmup_s)")
    p.add_argument("--window", type=positive_float,
                   help="baseline and pulse window after the warm-up, s (default: the "
                        "longest of [sumo] horizon_s, 90 s and 2 round trips + 60 s)")
    p.add_argument("--pulse-s", type=positive_float, default=25.0,
                   help="the pulse: the meter at its least plan for this long from the "
                        "window's start, s")
    p.add_argument("--level-s", type=positive_float, default=120.0,
                   help="each level of the release-rate staircase (and its lead-in), s")
    p.add_argument("--levels", type=positive_int, default=8,
                   help="staircase levels after the lead-in (+, 0, -, 0, ...: every four "
                        "give two steps up and two down)")
    p.add_argument("--step-veh-h", type=positive_float, default=200.0,
                   help="the staircase's release-rate step, veh/h")
    p.add_argument("--round-trip", type=positive_float,
                   help="round trip T of the pulse gate, s (default: the model's L / "
                        "min(lambda_1, lambda_3) + L / |lambda_4| at the scenario's "
                        "equilibrium)")
    p.add_argument("--smooth-s", type=positive_float, default=30.0,
                   help="moving mean of the pulse's deviation norm before its decay is "
                        "read, s")
    p.add_argument("--floor", choices=FLOORS, default="auto",
                   help="the pulse's noise floor: the baselines of two seeds (seeds), the "
                        "last quarter of the pulse's own deviation (late), none; auto: "
                        "seeds with two seeds or more, else late")
    add_parallel(p)
    add_out(p, "output directory (default results/premise/<scenario file name>); a restart "
               "with the same directory runs only what is missing")
    add_quiet(p)
    add_no_plots(p, "skip the figure")
    add_json(p, "print premise.json instead of the table")
    p.set_defaults(func=cmd_premise)
