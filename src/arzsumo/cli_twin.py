"""``arzsumo twin SCENARIO [--out DIR] [--json]``: run the nonlinear PDE twin;
``arzsumo reproduce [--out DIR] [--quick]``: run every experiment of section 5.

Registered into the main parser by :func:`register`; the work is done by
:func:`arzsumo.engines.twin.run_twin` and :func:`arzsumo.outputs.twin.write_run`, and by
:func:`arzsumo.studies.paper.reproduce.reproduce` and
:func:`arzsumo.studies.paper.report.write_reproduction`.
Exit codes: 0 completed, 3 stopped early (state left the physical domain; the partial
results are written and marked ``"complete": false``), 2 user error.
"""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

from arzsumo.cli_args import positive_int
from arzsumo.scenario import load_scenario
from arzsumo.units import veh_s_to_veh_h

log = logging.getLogger(__name__)

EXIT_INCOMPLETE = 3


def cmd_twin(args: argparse.Namespace) -> int:
    from arzsumo.engines.twin import run_twin
    from arzsumo.io import json_safe
    from arzsumo.outdir import OutputDir
    from arzsumo.outputs.twin import write_run

    sc = load_scenario(args.scenario)
    out = Path(args.out) if args.out else Path("results") / "twin" / sc.name
    with OutputDir(out, "twin", overwrite=args.overwrite) as target:  # checked before the run
        run = run_twin(sc, baseline=not args.no_baseline)
        write_run(run, target, plots=not args.no_plots)
    summary = run.summary()
    if args.json:
        print(json.dumps(json_safe(summary), indent=2))
    else:
        _print(summary, out)
    return 0 if run.result.complete else EXIT_INCOMPLETE


def _print(s: dict, out: Path) -> None:
    num = s["numerics"]
    print(f"twin {s['scenario']}: controller {s['controller']}, "
          f"{s['config']['cells']} cells, {s['config']['scheme']}")
    print(f"  status: {s['status']}")
    print(f"  simulated {s['final_time']:.1f} s in {num['wall_time_s']:.2f} s "
          f"({num['speed_up']:.0f}x real time, {num['steps']} steps)")
    print(f"  deviation norm: {s['initial_norm']:.4g} -> {s['final_norm']:.4g} "
          f"(ratio {s['final_norm_ratio']:.3g})")
    print(f"  triggers {s['triggers']}, release time {s['release_time']:.0f} s, "
          f"saturated {s['saturation_time']:.0f} s "
          f"(U in [{veh_s_to_veh_h(s['u_range'][0]):.0f}, "
          f"{veh_s_to_veh_h(s['u_range'][1]):.0f}] veh/h)")
    for key in ("J_fuel", "J_discom", "J_TTT", "total_delay"):
        v = s[key]
        line = f"  {key:<12} HV {v['h']:12.5g}  AV {v['a']:12.5g}  total {v['total']:12.5g}"
        rel = s["relative_to_open_loop_percent"]
        if rel is not None:
            line += f"   ({rel['total'][key]:+.2f} % vs open loop)"
        print(line)
    c = s["conservation"]
    print(f"  vehicles {c['vehicles_initial']:.3f} -> {c['vehicles_final']:.3f}, in "
          f"{c['inflow']:.3f}, out {c['outflow']:.3f}, balance error {c['balance_error']:.2e}")
    print(f"  written to {out}/")


def cmd_reproduce(args: argparse.Namespace) -> int:
    from arzsumo.outdir import OutputDir
    from arzsumo.studies.paper.compare import REPRODUCED, claims
    from arzsumo.studies.paper.report import write_reproduction
    from arzsumo.studies.paper.reproduce import reproduce

    out = Path(args.out) if args.out else Path("results") / "reproduce"
    with OutputDir(out, "reproduce", overwrite=args.overwrite) as target:
        from arzsumo.resources import shipped_scenarios_dir

        paper = args.scenarios or shipped_scenarios_dir() / "paper"
        rep = reproduce(paper, quick=args.quick, only=args.only or None,
                        workers=args.workers,
                        twin={"scheme": args.scheme} if args.scheme else None)
        write_reproduction(rep, target, plots=not args.no_plots)
    cl = claims(rep)
    print(f"reproduce: {len(rep.records)} runs, {rep.open_loops} open loops, "
          f"{rep.wall_time:.1f} s{' (quick)' if rep.quick else ''}")
    for c in cl:
        mark = "yes" if c.verdict == REPRODUCED else "NO "
        print(f"  [{mark}] {c.claim}: {c.ours}")
    print(f"  {sum(c.verdict == REPRODUCED for c in cl)} of {len(cl)} claims reproduced in "
          f"direction; report in {out}/report.md")
    incomplete = [r.name for r in rep.records if not r.summary["complete"]]
    if incomplete:
        print(f"  incomplete runs: {', '.join(incomplete)}")
    return 0 if not incomplete else EXIT_INCOMPLETE


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``twin`` subcommand to the main parser's subparsers."""
    p = subparsers.add_parser("twin", help="run the nonlinear PDE twin on a scenario",
                              description="Run the nonlinear mixed-autonomy ARZ model (the PDE "
                                          "twin) on a scenario with its [twin] controller and "
                                          "[initial] condition; write fields, summary, plots.")
    p.add_argument("scenario", metavar="SCENARIO.toml",
                   help="scenario file with optional [twin] and [initial] tables")
    p.add_argument("--out", metavar="DIR",
                   help="output directory (default results/twin/<scenario name>)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a previous twin result in the --out directory")
    p.add_argument("--json", action="store_true", help="print the summary as JSON (SI)")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    p.add_argument("--no-baseline", action="store_true",
                   help="do not run the open loop for relative changes")
    p.set_defaults(func=cmd_twin)

    r = subparsers.add_parser("reproduce",
                              help="run every experiment of section 5 and compare with the paper",
                              description="Run every section 5 experiment of the paper in the "
                                          "PDE twin, compare each claim with the paper's, and "
                                          "write a report.")
    r.add_argument("--out", metavar="DIR",
                   help="output directory (default results/reproduce)")
    r.add_argument("--overwrite", action="store_true",
                   help="replace a previous reproduce result in the --out directory")
    r.add_argument("--quick", action="store_true",
                   help="tiny grid and horizon: a smoke test, numbers not meaningful")
    r.add_argument("--scenarios", metavar="DIR", default=None,
                   help="directory of the section 5 scenario files (default: the shipped paper/ "
                        "scenarios)")
    r.add_argument("--only", metavar="NAME", nargs="*",
                   help="run only these scenario names")
    r.add_argument("--scheme", choices=("first", "muscl"),
                   help="override every scenario's [twin] scheme (files: first order)")
    r.add_argument("--workers", type=positive_int, default=1,
                   help="processes, an integer >= 1 (results do not depend on it)")
    r.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    r.set_defaults(func=cmd_reproduce)
