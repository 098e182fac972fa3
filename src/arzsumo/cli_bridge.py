"""CLI commands of the closed loop: ``arzsumo run`` and ``arzsumo compare``."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

import numpy as np

from arzsumo.errors import ScenarioError

log = logging.getLogger("arzsumo")

#: the default scenario of ``arzsumo run`` (and ``make run``)
DEFAULT_SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "default.toml"


def cmd_run(args: argparse.Namespace) -> int:
    from arzsumo.bridge.config import run_settings_from_dict
    from arzsumo.bridge.cosim import run_cosimulation
    from arzsumo.bridge.outputs import write_results
    from arzsumo.scenarios import design_from_dict, load_scenario
    from arzsumo.sumo.config import sumo_config_of

    path = Path(args.scenario) if args.scenario else DEFAULT_SCENARIO
    sc = load_scenario(path)
    raw = sc.raw
    settings = run_settings_from_dict(raw, sc.source, controller=args.controller)
    cfg = sumo_config_of(sc)
    if args.seed is not None:
        if args.seed < 0:
            raise ScenarioError(f"--seed = {args.seed} is not allowed: an integer >= 0")
        cfg = cfg.with_(seed=args.seed)
    if args.horizon is not None:
        cfg = cfg.with_(horizon=args.horizon)
    design = design_from_dict(raw, sc.source)
    initial = None
    if settings.start == "placement":
        from arzsumo.twin.config import twin_config_from_dict
        from arzsumo.twin.initial import initial_fields

        n = round(sc.params.length / cfg.cell_length)
        xc = (np.arange(n) + 0.5) * cfg.cell_length
        initial = initial_fields(twin_config_from_dict(raw, sc.source).initial,
                                 sc.equilibrium, xc)
    out = Path(args.out) if args.out else Path("results") / (
        f"{sc.name}-{settings.controller}-seed{cfg.seed}")
    res = run_cosimulation(sc, settings, cfg, design, initial_fields=initial,
                           progress=not args.quiet)
    text = path.read_text(encoding="utf-8") + "\n# resolved settings of this run\n" + \
        "\n".join(f"# {k} = {v!r}" for k, v in settings.as_dict().items()) + \
        f"\n# sumo = {cfg!r}\n"
    out, summ = write_results(res, out, text, plots=not args.no_plots)
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
    p.add_argument("scenario", nargs="?", help="scenario file (default scenarios/default.toml)")
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
