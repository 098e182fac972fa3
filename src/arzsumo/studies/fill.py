"""Fill-then-hold demand on the approach network (``arzsumo study fill``).

Each point is one open-loop SUMO run (fixed-cycle meter at its nominal plan) of the
shipped default scenario's network with its ``approach`` buffer before x = 0. The
mainline demand is ``--fill-h`` / ``--fill-a`` veh/h from t = 0 to ``--fill`` s (above
the merge's discharge: the queue fills the section from the merge), then the hold demand
of the point (``--holds HV:AV`` veh/h) to the end. After ``--warmup`` s, ``--measured``
s are measured on ``main`` with the measures of :mod:`arzsumo.studies.open_loop`; a
point is ``ok`` when it is stationary, congested under the model and inserts at least
98 % of its demand. The design the shipped default was chosen from is the default's
own fill and hold (3750:850 veh/h after 4200 + 1300 veh/h for 600 s).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import markdown_table, publish, write_csv
from arzsumo.studies.common import (
    FORMER_DEFAULT,
    StudyError,
    add_output,
    add_runs,
    fixed_cycle,
    non_negative_float,
    number_list,
    positive_float,
    print_list,
    scenario_data,
    shipped_scenario,
    study_spec,
)
from arzsumo.studies.design import StudyRun, design_runs, run_design
from arzsumo.units import veh_s_to_veh_h

NAME = "fill"
#: the results page this study keeps a block of
PAGE = "sumo_fill"
#: the columns the page's table shows
SHOWN = ["hold", "green_share", "seed", "slope_veh_min", "kendall_p", "drift_rel",
         "rho_h_veh_km", "rho_a_veh_km", "v_h_kmh", "v_a_kmh", "sd_v_h_kmh",
         "outflow_veh_h", "inserted_main", "queue_m_end", "lambda4_kmh", "ok"]


def hold_pair(text: str) -> tuple[float, float]:
    """``HV:AV`` veh/h, e.g. ``3750:850``."""
    try:
        h, a = (float(v) for v in text.split(":"))
    except ValueError:
        raise StudyError(f"--holds: {text!r} is not allowed: HV:AV demands in veh/h, e.g. "
                         "3750:850") from None
    if h < 0 or a < 0:
        raise StudyError(f"--holds: {text!r} is not allowed: demands >= 0 veh/h")
    return h, a


def design(holds: list[str], greens: list[float], sigmas: list[float], seeds: list[int],
           fill: tuple[float, float, float] = (4200.0, 1300.0, 600.0),
           approach: float = 2500.0, warmup: float = 600.0, measured: float = 450.0,
           step: float = 0.1) -> list[StudyRun]:
    """The runs: hold demand x green share x sigma x seed; ``fill``: (HV veh/h, AV veh/h,
    duration s) of the fill phase."""
    path = shipped_scenario(FORMER_DEFAULT)
    pairs = [hold_pair(h) for h in holds]
    spec = study_spec(
        NAME, path, fixed_cycle(scenario_data(path)), seeds=list(seeds),
        set={"sumo.fill_demand_h_veh_h": fill[0], "sumo.fill_demand_a_veh_h": fill[1],
             "sumo.fill_s": fill[2], "sumo.approach_length_m": approach,
             "sumo.step_length_s": step, "run.warmup_s": warmup, "sumo.horizon_s": measured},
        axis=[{"name": "hold", "values": list(holds),
               "set": [{"sumo.demand_h_veh_h": h, "sumo.demand_a_veh_h": a} for h, a in pairs]},
              {"field": "sumo.green_share", "values": list(greens)},
              {"field": "sumo.hv_sigma", "values": list(sigmas)}])
    return design_runs(spec, {"fill_h_veh_h": fill[0], "fill_a_veh_h": fill[1],
                              "fill_s": fill[2], "approach_m": approach, "step_s": step,
                              "warmup_s": warmup, "measured_s": measured})


def run_point(run: StudyRun) -> dict[str, Any]:
    """One fill-then-hold run; its row (units in the column names)."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.studies.open_loop import run_measures

    t0 = time.perf_counter()
    sc = scenario_from_dict(run.scenario, run.source)
    cfg = sc.sumo.with_(horizon=sc.run.warmup + sc.sumo.horizon)
    row: dict[str, Any] = {**dict(run.columns),
                           "hold_h_veh_h": veh_s_to_veh_h(sc.sumo.demand_h),
                           "hold_a_veh_h": veh_s_to_veh_h(sc.sumo.demand_a), **dict(run.options)}
    row.update(run_measures(sc.params, cfg, sc.run.warmup))
    row["ok"] = int(row["stationary"] and row["lambda4_kmh"] < 0
                    and row["inserted_main"] >= 0.98)
    row["wall_s"] = time.perf_counter() - t0
    return row


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The fill study's options."""
    parser.add_argument("--holds", nargs="+", default=["3750:850"], metavar="HV:AV",
                        help="hold demands, veh/h")
    parser.add_argument("--fill-h", type=non_negative_float, default=4200.0,
                        help="HV fill demand, veh/h")
    parser.add_argument("--fill-a", type=non_negative_float, default=1300.0,
                        help="AV fill demand, veh/h")
    parser.add_argument("--fill", type=non_negative_float, default=600.0,
                        help="fill phase, s")
    parser.add_argument("--greens", type=number_list, default=[0.5],
                        help="nominal green shares (default: 0.5)")
    parser.add_argument("--sigmas", type=number_list, default=[0.5],
                        help="Krauss sigma of the HVs (default: 0.5)")
    add_runs(parser, seeds="1")
    parser.add_argument("--approach", type=positive_float, default=2500.0,
                        help="buffer length before x = 0, m")
    parser.add_argument("--warmup", type=positive_float, default=600.0, help="s not measured")
    parser.add_argument("--measured", type=positive_float, default=450.0, help="s measured")
    parser.add_argument("--step", type=positive_float, default=0.1, help="SUMO step, s")
    add_output(parser, NAME, PAGE, plots=False)


def run(args: argparse.Namespace) -> int:
    """Run the missing points and write the table (and the page with ``--docs``)."""
    runs = design(args.holds, args.greens, args.sigmas, args.seeds,
                  (args.fill_h, args.fill_a, args.fill), args.approach, args.warmup,
                  args.measured, args.step)
    if args.list:
        return print_list([r.run_id for r in runs])
    with resumable_dir(args.out, f"study-{NAME}") as out:
        df = pd.DataFrame(run_design(runs, run_point, out, workers=args.workers,
                                     scheduler=args.scheduler, progress=not args.quiet,
                                     label=NAME))
        path = write_csv(df, out / "fill.csv", "%.5g")
        text = markdown_table(df[[c for c in SHOWN if c in df]])
        if args.docs is not None:
            publish(args.docs, PAGE, NAME, "Fill-then-hold demand in SUMO",
                    f"{len(df)} runs (`arzsumo study {NAME}`); {int(df['ok'].sum())} ok. "
                    f"Table: [{PAGE}.csv]({PAGE}/{PAGE}.csv).\n\n{text}",
                    [(path, f"{PAGE}.csv")])
    print(text)
    return 0
