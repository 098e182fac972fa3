"""SUMO commands of the CLI: ``arzsumo build-net`` and ``arzsumo calibrate``.

Registered by :func:`register` from :func:`arzsumo.cli.build_parser`; SUMO is imported
only when one of these commands runs.
"""

from __future__ import annotations

import argparse
import logging
import os

from arzsumo.cli_args import non_negative_float, positive_float, positive_int, seed_int
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

log = logging.getLogger("arzsumo")


def cmd_build_net(args: argparse.Namespace) -> int:
    from arzsumo.model.params import get_preset
    from arzsumo.sumo.config import SumoConfig
    from arzsumo.sumo.demand import write_gui_files
    from arzsumo.sumo.network import NetworkSpec, edge_lengths, rebuild_network
    from arzsumo.sumo.paths import CONFIG_FILE, NET_FILE, ROUTE_FILE, build_nets_dir

    out = build_nets_dir(args.out)
    spec = NetworkSpec(approach_length=args.approach_length)
    net, changed = rebuild_network(out, spec, write=not args.keep_sources)
    write_gui_files(out, get_preset("paper_base").params,
                    SumoConfig(approach_length=args.approach_length), NET_FILE, ROUTE_FILE,
                    CONFIG_FILE)
    lengths = edge_lengths(net)
    print(f"network: {net} ({'written' if changed else 'unchanged'})")
    print("edges (m): " + ", ".join(f"{k} {v:.2f}" for k, v in sorted(lengths.items())))
    print(f"sumo-gui: {out / CONFIG_FILE}")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    from arzsumo.outdir import OutputDir
    from arzsumo.outputs.calibration import write_calibration
    from arzsumo.scenario import load_scenario, scenario_from_preset
    from arzsumo.sumo.calibrate import CalibrationPlan, calibrate

    sc = load_scenario(args.scenario) if args.scenario else scenario_from_preset(args.preset)
    cfg = sc.sumo
    changes = {"seed": args.seed, "step_length": args.step_length}
    cfg = cfg.with_(**{k: v for k, v in changes.items() if v is not None})
    plan = CalibrationPlan()
    if args.quick:
        plan = CalibrationPlan(horizon=90.0, warmup=30.0, window=10.0,
                               curve_shares=(0.0, 1.0), fd_levels=("light",),
                               fd_shares=(1.0,), min_samples=5.0)
    if args.horizon is not None:
        plan = CalibrationPlan(**{**plan.__dict__, "horizon": args.horizon,
                                  "warmup": min(plan.warmup, args.horizon / 3)})
    with OutputDir(args.out, "calibration", overwrite=args.overwrite) as target:
        cal = calibrate(sc.params, cfg, plan, jobs=args.jobs)
        write_calibration(target, cal, cfg)
    out = args.out
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
    print(f"written: {out}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the SUMO subcommands to the CLI's subparsers."""
    p = sub.add_parser("build-net", help="write the SUMO network sources and build the network",
                       description="Write the XML sources of the on-ramp network, build it "
                                   "with netconvert, and write sumo-gui files.")
    p.add_argument("--out", metavar="DIR",
                   help="network directory (default: $ARZSUMO_SUMO_NETS, else sumo_nets/ of "
                        "a source checkout)")
    p.add_argument("--keep-sources", action="store_true",
                   help="rebuild from the XML sources in DIR instead of rewriting them")
    p.add_argument("--approach-length-m", dest="approach_length", type=non_negative_float,
                   default=0.0, metavar="M",
                   help="length of the approach edge before x = 0 where mainline vehicles "
                        "are inserted (default 0: none, the shipped network)")
    p.set_defaults(func=cmd_build_net)

    p = sub.add_parser("calibrate", help="fit the AO fundamental diagram and the meter curve "
                                         "to SUMO runs",
                       description="Run SUMO at several demands and meter plans, fit the AO "
                                   "fundamental diagram per class and the meter's outflow "
                                   "curve, and write them.")
    src = p.add_mutually_exclusive_group()
    src.add_argument("--preset", default="paper_base", help="model preset for vehicle types")
    src.add_argument("--scenario", metavar="FILE.toml", help="scenario file (may hold [sumo])")
    p.add_argument("--out", metavar="DIR", default="runs/calibration",
                   help="output directory (written atomically)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a previous calibration result in the --out directory")
    p.add_argument("--seed", type=seed_int,
                   help="SUMO seed in [0, 2^31) (default: the scenario's [sumo] seed)")
    p.add_argument("--step-length", type=positive_float,
                   help="SUMO step, s (default: the scenario's [sumo] step_length_s)")
    p.add_argument("--horizon", type=positive_float,
                   help="length of each run, s (default 450; 90 with --quick)")
    p.add_argument("--jobs", type=positive_int, default=min(2, os.cpu_count() or 1),
                   help="SUMO runs at a time (default: up to 2)")
    p.add_argument("--quick", action="store_true",
                   help="a tiny smoke calibration (3 short runs)")
    p.set_defaults(func=cmd_calibrate)
