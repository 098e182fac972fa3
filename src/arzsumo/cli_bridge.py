"""CLI commands of the closed loop: ``arzsumo run``, ``arzsumo compare`` and
``arzsumo alinea-target`` (ALINEA's target from open-loop runs)."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path
from typing import TYPE_CHECKING

from arzsumo.cli_args import non_negative_float, positive_float, seed_int, seed_list
from arzsumo.control.registry import controller_names

if TYPE_CHECKING:
    import numpy as np

    from arzsumo.scenario import Scenario

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


def _loop_samples(args: argparse.Namespace, sc: Scenario
                  ) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """(seed, occupancy, flow) per open-loop run (1 s samples), SUMO runs or ``--runs``."""
    import numpy as np
    import pyarrow.parquet as pq

    from arzsumo.bridge.session import meter_curve_of
    from arzsumo.errors import ScenarioError
    from arzsumo.sumo.loop_curve import record_downstream_loop

    out = []
    for run_dir in args.runs or ():
        path = Path(run_dir) / "periods.parquet"
        if not path.is_file():
            raise ScenarioError(f"--runs {run_dir} is not allowed: no periods.parquet there")
        table = pq.read_table(path).to_pandas()
        if "flow_out_loop" not in table:
            raise ScenarioError(f"--runs {run_dir} is not allowed: its periods table has no "
                                "flow_out_loop (a run from before the ALINEA loop)")
        seed = json.loads((Path(run_dir) / "summary.json").read_text()).get("seed", -1)
        out.append((int(seed), np.asarray(table["occupancy_out"], float),
                    np.asarray(table["flow_out_loop"], float)))
    duration = args.duration or sc.run.warmup + sc.sumo.horizon
    for seed in args.seeds or ():
        cfg = sc.sumo.with_(seed=seed, horizon=duration)
        log.info("open loop, seed %d, %g s", seed, duration)
        series = record_downstream_loop(sc.params, cfg, sc.alinea.loop_distance,
                                        meter_curve_of(cfg, sc.source))
        out.append((seed, series.occupancy, series.flow))
    return out


def cmd_alinea_target(args: argparse.Namespace) -> int:
    import numpy as np

    from arzsumo.errors import ScenarioError
    from arzsumo.evaluation.critical_occupancy import critical_occupancy, period_means
    from arzsumo.outdir import OutputDir
    from arzsumo.outputs.alinea import write_alinea_target
    from arzsumo.scenario import load_scenario

    sc = load_scenario(args.scenario)
    if not args.seeds and not args.runs:
        raise ScenarioError("--seeds or --runs is needed: open-loop runs to read the loop from")
    period, dt = sc.alinea.period, sc.sumo.control_period
    with OutputDir(args.out, "alinea-target", overwrite=args.overwrite) as target:
        raw = _loop_samples(args, sc)
        means = [(seed, *period_means(o, q, dt, period)) for seed, o, q in raw]
        crit = critical_occupancy(np.concatenate([m[1] for m in means]),
                                  np.concatenate([m[2] for m in means]), share=args.share)
        meta = {"scenario": str(args.scenario), "seeds": [m[0] for m in means],
                "period_s": period, "loop_distance_m": sc.alinea.loop_distance,
                "duration_s": args.duration or sc.run.warmup + sc.sumo.horizon,
                "runs": list(args.runs or ())}
        title = (f"{sc.name}: loop {sc.alinea.loop_distance:g} m past the merge, "
                 f"{period:g} s means")
        write_alinea_target(target, means, crit, meta, title)
    bound = ("" if crit.saturated else "; flow never saturated: a lower bound, the 98th "
             "percentile of the occupancies")
    print(f"critical occupancy {100 * crit.critical:.2f} % ({crit.samples} period means, "
          f"fit capacity {crit.fit.capacity * 3600:.0f} veh/h{bound}); "
          f"target {100 * crit.target:.2f} % = {crit.share:g} x critical")
    print(f"[alinea] target_pct = {100 * crit.target:.1f}")
    print(f"results: {args.out}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``run``, ``compare`` and ``alinea-target`` to the top-level parser."""
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
    _register_alinea_target(sub)


def _register_alinea_target(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("alinea-target", help="ALINEA's target from the loop's flow-occupancy "
                                             "curve in open-loop runs",
                       description="Run open loops of a scenario (or read run directories), "
                                   "average ALINEA's loop over the [alinea] period, fit the "
                                   "triangular flow-occupancy curve, and print the critical "
                                   "occupancy and the suggested target; write samples.csv, "
                                   "curve.csv, target.json and curve.png to --out.")
    p.add_argument("scenario", metavar="SCENARIO.toml", help="scenario file")
    p.add_argument("--seeds", type=seed_list, metavar="SEEDS",
                   help="SUMO seeds of open-loop runs, comma-separated, A-B for a range")
    p.add_argument("--runs", nargs="+", metavar="RUN_DIR",
                   help="results directories of arzsumo run to read instead of (or besides) "
                        "running SUMO")
    p.add_argument("--duration", type=positive_float,
                   help="simulated time of each open-loop run from t = 0, s (default: "
                        "[run] warmup_s + [sumo] horizon_s)")
    p.add_argument("--share", type=positive_float, default=0.9,
                   help="target as a share of the critical occupancy (in (0, 1])")
    p.add_argument("--out", metavar="DIR", required=True, help="output directory")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a previous alinea-target result in --out")
    p.set_defaults(func=cmd_alinea_target)
