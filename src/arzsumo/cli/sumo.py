"""SUMO commands of the CLI: ``arzsumo build-net``, ``arzsumo calibrate`` and
``arzsumo alinea-target`` (ALINEA's target from open-loop runs)."""

from __future__ import annotations

import argparse
import json
import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING

from arzsumo.argtypes import non_negative_float, positive_float, positive_int
from arzsumo.cli.options import (
    add_model_source,
    add_out,
    add_overwrite,
    add_scenario,
    add_seed,
    add_seeds,
)
from arzsumo.cli.scenarios import load_named, scenario_of
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

if TYPE_CHECKING:
    import numpy as np

    from arzsumo.scenario import Scenario

log = logging.getLogger("arzsumo")


def cmd_build_net(args: argparse.Namespace) -> int:
    from arzsumo.model.params import get_preset
    from arzsumo.sumo.config import SumoConfig
    from arzsumo.sumo.demand import write_gui_files
    from arzsumo.sumo.network import NetworkSpec, edge_lengths, rebuild_network
    from arzsumo.sumo.paths import CONFIG_FILE, NET_FILE, ROUTE_FILE, build_nets_dir

    out = build_nets_dir(args.out)
    spec = NetworkSpec(approach_length=args.approach_length,
                       approach_piece=args.approach_piece)
    net, changed = rebuild_network(out, spec, write=not args.keep_sources)
    write_gui_files(out, get_preset("paper_base").params,
                    SumoConfig(approach_length=args.approach_length,
                               approach_piece=args.approach_piece),
                    NET_FILE, ROUTE_FILE, CONFIG_FILE)
    lengths = edge_lengths(net)
    print(f"network: {net} ({'written' if changed else 'unchanged'})")
    print("edges (m): " + ", ".join(f"{k} {v:.2f}" for k, v in sorted(lengths.items())))
    print(f"sumo-gui: {out / CONFIG_FILE}")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    from arzsumo.api.calibration import calibrate

    scenario = args.scenario or scenario_of(args)   # --preset: its scenario
    cal = calibrate(scenario, out=args.out, quick=args.quick, horizon_s=args.horizon,
                    seed=args.seed, step_length_s=args.step_length, jobs=args.jobs,
                    overwrite=args.overwrite)
    for cls, name in (("h", "HV"), ("a", "AV")):
        f = cal.fits[cls]
        print(f"{name}: V = {ms_to_kmh(f.v_free):.1f} km/h, AO_max = {f.ao_max:.3f}, "
              f"gamma = {f.gamma:.2f}; R^2 = {f.r2:.3f}, RMSE = {ms_to_kmh(f.rmse):.2f} km/h "
              f"({f.n} cells); paper curve R^2 = {f.r2_paper:.3f}")
    print("outflow vs green share: " + ", ".join(
        f"{g:.2f} -> {veh_s_to_veh_h(q):.0f} veh/h"
        for g, q in zip(cal.curve.green_share, cal.curve.outflow, strict=True)))
    eq = cal.equilibrium
    print(f"medium demand, green share {eq['green_share']:.2f}: "
          f"HV {veh_m_to_veh_km(eq['rho_h']):.1f} veh/km at {ms_to_kmh(eq['v_h']):.1f} km/h, "
          f"AV {veh_m_to_veh_km(eq['rho_a']):.1f} veh/km at {ms_to_kmh(eq['v_a']):.1f} km/h, "
          f"AO {eq['ao']:.3f}; mainline inflow {veh_s_to_veh_h(eq['inflow']):.0f} veh/h, "
          f"outflow {veh_s_to_veh_h(eq['outflow']):.0f} veh/h")
    if "eigenvalues" in eq:
        lam = [ms_to_kmh(v) for v in eq["eigenvalues"]]
        print(f"calibrated model there: v_h {ms_to_kmh(eq['model_v_h']):.1f} km/h, v_a "
              f"{ms_to_kmh(eq['model_v_a']):.1f} km/h; lambda = "
              + ", ".join(f"{v:.2f}" for v in lam) + f" km/h; regime {eq['regime']}")
    else:
        print(f"regime: {eq.get('regime')} ({eq.get('note', '')})")
    print(f"written: {args.out}")
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

    path, sc = load_named(args.scenario)
    if not args.seeds and not args.runs:
        raise ScenarioError("--seeds or --runs is needed: open-loop runs to read the loop from")
    period, dt = sc.alinea.period, sc.sumo.control_period
    with OutputDir(args.out, "alinea-target", overwrite=args.overwrite) as target:
        raw = _loop_samples(args, sc)
        means = [(seed, *period_means(o, q, dt, period)) for seed, o, q in raw]
        crit = critical_occupancy(np.concatenate([m[1] for m in means]),
                                  np.concatenate([m[2] for m in means]), share=args.share)
        meta = {"scenario": str(path), "seeds": [m[0] for m in means],
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
    """Add ``build-net``, ``calibrate`` and ``alinea-target`` to the top-level parser."""
    p = sub.add_parser("build-net", help="write the SUMO network sources and build the network",
                       description="Write the XML sources of the on-ramp network, build it "
                                   "with netconvert, and write sumo-gui files.")
    add_out(p, "network directory (default: $ARZSUMO_SUMO_NETS, else sumo_nets/ of a "
               "source checkout)")
    p.add_argument("--keep-sources", action="store_true",
                   help="rebuild from the XML sources in DIR instead of rewriting them")
    p.add_argument("--approach-length-m", dest="approach_length", type=non_negative_float,
                   default=0.0, metavar="M",
                   help="length of the approach edge before x = 0 where mainline vehicles "
                        "are inserted (default 0: none, the shipped network)")
    p.add_argument("--approach-piece-m", dest="approach_piece", type=non_negative_float,
                   default=0.0, metavar="M",
                   help="cut the approach into edges of at most M m (default 0: one edge)")
    p.set_defaults(func=cmd_build_net)

    p = sub.add_parser("calibrate", help="fit the AO fundamental diagram and the meter curve "
                                         "to SUMO runs",
                       description="Run SUMO at several demands and meter plans, fit the AO "
                                   "fundamental diagram per class and the meter's outflow "
                                   "curve, and write them.")
    add_model_source(p, preset_help="model preset for vehicle types",
                     scenario_help="scenario file (may hold [sumo])")
    add_out(p, "output directory (written atomically)", default="runs/calibration")
    add_overwrite(p, "calibration")
    add_seed(p, "the scenario's [sumo] seed")
    p.add_argument("--step-length", type=positive_float,
                   help="SUMO step, s (default: the scenario's [sumo] step_length_s)")
    p.add_argument("--horizon", type=positive_float,
                   help="length of each run, s (default 450; 90 with --quick)")
    p.add_argument("--jobs", type=positive_int, default=min(2, os.cpu_count() or 1),
                   help="SUMO runs at a time (default: up to 2)")
    p.add_argument("--quick", action="store_true",
                   help="a tiny smoke calibration (3 short runs)")
    p.set_defaults(func=cmd_calibrate)

    p = sub.add_parser("alinea-target", help="ALINEA's target from the loop's flow-occupancy "
                                             "curve in open-loop runs",
                       description="Run open loops of a scenario (or read run directories), "
                                   "average ALINEA's loop over the [alinea] period, fit the "
                                   "triangular flow-occupancy curve, and print the critical "
                                   "occupancy and the suggested target; write samples.csv, "
                                   "curve.csv, target.json and curve.png to --out.")
    add_scenario(p)
    add_seeds(p, "SUMO seeds of open-loop runs")
    p.add_argument("--runs", nargs="+", metavar="RUN_DIR",
                   help="results directories of arzsumo run to read instead of (or besides) "
                        "running SUMO")
    p.add_argument("--duration", type=positive_float,
                   help="simulated time of each open-loop run from t = 0, s (default: "
                        "[run] warmup_s + [sumo] horizon_s)")
    p.add_argument("--share", type=positive_float, default=0.9,
                   help="target as a share of the critical occupancy (in (0, 1])")
    add_out(p, "output directory", required=True)
    add_overwrite(p, "alinea-target")
    p.set_defaults(func=cmd_alinea_target)
