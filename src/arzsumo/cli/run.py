"""``arzsumo run [SCENARIO]``: one closed loop in SUMO with the PDE twins alongside
(:func:`arzsumo.api.runs.prepare`, then :func:`arzsumo.api.runs.run_checked`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from arzsumo.argtypes import positive_float
from arzsumo.cli.options import (
    add_json,
    add_no_plots,
    add_out,
    add_overwrite,
    add_quiet,
    add_scenario,
    add_seed,
    add_warmup,
)
from arzsumo.cli.scenarios import load_named
from arzsumo.control.registry import controller_names


def cmd_run(args: argparse.Namespace) -> int:
    from arzsumo.api.runs import prepare, run_checked
    from arzsumo.bridge.run_progress import WRITING, run_progress
    from arzsumo.bridge.session import CLI_NAMES, default_run_name
    from arzsumo.outdir import OutputDir, check_target
    from arzsumo.sumo.frontend import Frontend

    # a shipped name or the shipped default is found in the package: any directory will do
    _, sc = load_named(args.scenario)
    fcd = True if args.fcd else None   # without --fcd the scenario's [sumo] fcd holds
    prepared = prepare(sc, controller=args.controller, seed=args.seed,
                       horizon_s=args.horizon, warmup_s=args.warmup, fcd=fcd,
                       allow_short_warmup=args.allow_short_warmup, names=CLI_NAMES)
    frontend = "gui" if args.gui else "libsumo"
    Frontend(frontend).check()   # no display or no sumo-gui: one line, before any output
    out = Path(args.out) if args.out else Path("results") / default_run_name(
        sc, prepared.settings, prepared.sumo)
    if args.dry_run:
        check_target(out, "run", overwrite=args.overwrite)   # as the run would refuse it
        print(prepared.describe())
        return 0
    # the output is checked and claimed before SUMO starts; Ctrl-C or an error removes it
    bar = run_progress(prepared.settings, prepared.sumo, enabled=not args.quiet,
                       writing=True)
    with OutputDir(out, "run", overwrite=args.overwrite) as target, bar:
        result = run_checked(prepared, progress=bar, frontend=frontend)
        bar.enter(WRITING)
        result.save(target, plots=not args.no_plots)
    summ = result.summary.to_dict()
    if args.json:
        from arzsumo.io import json_safe

        print(json.dumps(json_safe(summ), indent=2))
    else:
        from arzsumo.bridge.compare import key_table, updates_line
        from arzsumo.outputs.bridge import SUMMARY_CSV

        print(key_table(summ, str(out / SUMMARY_CSV)))
        if line := updates_line(summ):
            print(line)
        print(f"results: {out}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``run`` to the top-level parser."""
    p = sub.add_parser("run", help="closed loop in SUMO with the PDE twin alongside",
                       description="Run a scenario's closed loop in SUMO: warm-up under the "
                                   "nominal meter, then the [run] controller on the ramp "
                                   "meter, with the PDE twins alongside; write the results.")
    add_scenario(p, optional=True)
    add_out(p, "results directory (default results/NAME-CONTROLLER-seedN-hTs)")
    add_overwrite(p, "run")
    add_seed(p, "[sumo] seed")
    p.add_argument("--controller", choices=list(controller_names("sumo")),
                   help="controller (default: [run] controller)")
    p.add_argument("--horizon", type=positive_float,
                   help="control horizon after the warm-up, s; at least one control period "
                        "(default: [sumo] horizon_s)")
    add_warmup(p, "warm-up under the nominal meter before control, s; at least the "
                  "scenario's fill phase (default: [run] warmup_s; the name of the default "
                  "--out then ends in -wWs)")
    p.add_argument("--dry-run", action="store_true",
                   help="check the scenario and the options as the run would, print what "
                        "it would do, and exit without starting SUMO")
    p.add_argument("--fcd", action="store_true",
                   help="keep SUMO's trajectories of every vehicle every step in "
                        "fcd.xml.gz (as [sumo] fcd = true)")
    p.add_argument("--gui", action="store_true",
                   help="watch the run in sumo-gui (driven through TraCI; slower; needs a "
                        "display)")
    add_quiet(p)
    add_no_plots(p)
    add_json(p, "print the summary as JSON")
    p.set_defaults(func=cmd_run)
