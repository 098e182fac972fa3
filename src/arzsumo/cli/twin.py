"""``arzsumo twin SCENARIO [--controller NAME] [--out DIR] [--json]``: the nonlinear PDE twin
(:func:`arzsumo.api.runs.twin`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from arzsumo.cli.options import add_json, add_no_plots, add_out, add_overwrite, add_scenario
from arzsumo.cli.scenarios import load_named
from arzsumo.control.registry import controller_names
from arzsumo.errors import EXIT_INCOMPLETE
from arzsumo.units import veh_s_to_veh_h

#: (summary key, printed name, unit, factor from the summary's SI value); the times in
#: veh h as ``arzsumo run`` prints them (docs/outputs.md: the indices and their units)
INDICES = (("J_TTT", "J_TTT", "veh h", 1 / 3600),
           ("total_delay", "total delay", "veh h", 1 / 3600),
           ("J_fuel", "J_fuel", "veh", 1.0),
           ("J_discom", "J_discom", "veh m^2/s^3 + veh m^2/s^5", 1.0))


def cmd_twin(args: argparse.Namespace) -> int:
    from arzsumo.api.runs import twin, twin_controller
    from arzsumo.io import json_safe
    from arzsumo.outdir import OutputDir

    _, sc = load_named(args.scenario)
    sc, origin = twin_controller(sc, args.controller)
    out = Path(args.out) if args.out else Path("results") / "twin" / sc.name
    with OutputDir(out, "twin", overwrite=args.overwrite) as target:  # checked before the run
        result = twin(sc, baseline=not args.no_baseline)
        result.save(target, plots=not args.no_plots)
    summary = result.summary.to_dict()
    if args.json:
        print(json.dumps(json_safe(summary), indent=2))
    else:
        print_summary(summary, out, origin)
    return 0 if result.complete else EXIT_INCOMPLETE


def _index_line(s: dict, key: str, name: str, unit: str, factor: float) -> str:
    v = s[key]
    line = (f"  {name} ({unit})".ljust(42) + f" HV {v['h'] * factor:10.4g}  AV "
            f"{v['a'] * factor:10.4g}  total {v['total'] * factor:10.4g}")
    rel = s["relative_to_open_loop_percent"]
    if rel is not None:
        line += f"   ({rel['total'][key]:+.2f} % vs open loop)"
    return line


def print_summary(s: dict, out: Path, origin: str = "[twin] controller") -> None:
    """The twin's summary in human units (veh h, veh/h, s), each line with its units."""
    num = s["numerics"]
    print(f"twin {s['scenario']}: controller {s['controller']} (from {origin}), "
          f"{s['config']['cells']} cells, {s['config']['scheme']}")
    print(f"  status: {s['status']}")
    print(f"  simulated {s['final_time']:.1f} s in {num['wall_time_s']:.2f} s "
          f"({num['speed_up']:.0f}x real time, {num['steps']} steps)")
    print(f"  relative deviation norm (dimensionless): {s['initial_norm']:.4g} -> "
          f"{s['final_norm']:.4g} "
          f"(ratio {s['final_norm_ratio']:.3g})")
    print(f"  triggers {s['triggers']}, release time {s['release_time']:.0f} s, "
          f"saturated {s['saturation_time']:.0f} s "
          f"(U in [{veh_s_to_veh_h(s['u_range'][0]):.0f}, "
          f"{veh_s_to_veh_h(s['u_range'][1]):.0f}] veh/h)")
    for index in INDICES:
        print(_index_line(s, *index))
    c = s["conservation"]
    print(f"  vehicles (veh) {c['vehicles_initial']:.3f} -> {c['vehicles_final']:.3f}, in "
          f"{c['inflow']:.3f}, out {c['outflow']:.3f}, balance error {c['balance_error']:.2e}")
    print(f"  written to {out}/")


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``twin`` to the top-level parser."""
    p = sub.add_parser("twin", help="run the nonlinear PDE twin on a scenario",
                       description="Run the nonlinear mixed-autonomy ARZ model (the PDE "
                                   "twin) on a scenario with its [initial] condition and "
                                   "its controller (--controller, else [twin] controller, "
                                   "else [run] controller, else the open loop); write "
                                   "fields, summary, plots.")
    add_scenario(p, "scenario file with optional [twin] and [initial] tables")
    p.add_argument("--controller", choices=list(controller_names("twin")),
                   help="controller of the run (default: [twin] controller, else [run] "
                        "controller when it runs in the twin, else open)")
    add_out(p, "output directory (default results/twin/<scenario name>)")
    add_overwrite(p, "twin")
    add_json(p, "print the summary as JSON (SI)")
    add_no_plots(p)
    p.add_argument("--no-baseline", action="store_true",
                   help="do not run the open loop for relative changes")
    p.set_defaults(func=cmd_twin)
