"""Where SUMO holds a stationary congested section: the open loop over mainline demand x
green share (``arzsumo study approach``).

Each point is one open-loop SUMO run (fixed-cycle meter at its nominal plan, no fill
phase) of the former default scenario (lateral_files)'s network, with its ``approach`` buffer edge
before x = 0: mainline demand (HV + AV at ``--av-share``) x nominal green share x Krauss
sigma x seed, started from a congested section (``--empty-start``: from an empty one).
After ``--warmup`` s, ``--measured`` s are measured on ``main``
(:mod:`arzsumo.studies.open_loop`: stationarity, densities, speeds, speed sd, flows,
insertion, the approach queue, lambda_4 under the scenario's model).

``map.csv`` has one row per run, ``map.png`` the map: the demand x green-share grid of
the largest group of runs (same step, sigma, warm-up, buffer length and AV share; seeds
averaged per point), and every run's trend against stop-and-go and insertion against
the buffer queue. A point *qualifies* (:func:`qualifies`) when it is stationary,
congested under the model, shows stop-and-go and inserts its demand. ``--from CSV``
draws the map of an earlier table instead of running SUMO.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import publish, remove_stale_figures, write_csv
from arzsumo.studies.common import (
    FORMER_DEFAULT,
    StudyError,
    add_output,
    add_runs,
    fixed_cycle,
    fraction,
    number_list,
    plots_wanted,
    positive_float,
    print_list,
    scenario_data,
    shipped_scenario,
    study_spec,
)
from arzsumo.studies.design import StudyRun, design_runs, run_design

NAME = "approach"
#: the results page this study keeps a block of
PAGE = "sumo_map"
#: the default scenario's mainline AV share in the map's design (1560 of 5664 veh/h)
AV_SHARE = 1560.0 / 5664.0
#: visible stop-and-go: HV speed sd over cells x periods at least this, km/h
SD_MIN_KMH = 10.0
#: the mainline demand counts as inserted from this fraction on
INSERTED_MIN = 0.98
#: one group of grid panels per combination of these
GROUP = ["step_s", "hv_sigma", "warmup_s", "approach_m", "av_share"]


def design(demands: list[float], greens: list[float], sigmas: list[float], seeds: list[int],
           approach: float = 1500.0, warmup: float = 150.0, measured: float = 450.0,
           step: float = 0.1, initial: bool = True, av_share: float = AV_SHARE
           ) -> list[StudyRun]:
    """The runs of the map: demand x green share x sigma x seed."""
    path = shipped_scenario(FORMER_DEFAULT)
    sets = [{"sumo.demand_h_veh_h": d * (1 - av_share), "sumo.demand_a_veh_h": d * av_share}
            for d in demands]
    spec = study_spec(
        NAME, path, fixed_cycle(scenario_data(path)), seeds=list(seeds),
        set={"sumo.approach_length_m": approach, "sumo.step_length_s": step,
             "sumo.fill_s": 0.0, "run.warmup_s": warmup, "sumo.horizon_s": measured},
        axis=[{"name": "demand_veh_h", "values": list(demands), "set": sets},
              {"field": "sumo.green_share", "values": list(greens)},
              {"field": "sumo.hv_sigma", "values": list(sigmas)}])
    return design_runs(spec, {"initial": initial, "av_share": av_share, "approach_m": approach,
                              "step_s": step, "warmup_s": warmup, "measured_s": measured})


def run_point(run: StudyRun) -> dict[str, Any]:
    """One open-loop run of the map; its row (units in the column names)."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.studies.open_loop import initial_vehicles, run_measures

    t0 = time.perf_counter()
    sc = scenario_from_dict(run.scenario, run.source)
    opt = run.options
    cfg = sc.sumo.with_(horizon=sc.run.warmup + sc.sumo.horizon)
    init = initial_vehicles(sc.params, cfg) if opt["initial"] else []
    row = {**dict(run.columns), "initial": int(opt["initial"]),
           **{k: opt[k] for k in ("av_share", "approach_m", "step_s", "warmup_s",
                                  "measured_s")}}
    row.update(run_measures(sc.params, cfg, sc.run.warmup, init))
    row["wall_s"] = time.perf_counter() - t0
    return row


def qualifies(df: pd.DataFrame) -> pd.Series:
    """Stationary, congested under the model, visible stop-and-go, demand inserted."""
    return ((df["stationary"] >= 0.5) & (df["lambda4_kmh"] < 0)
            & (df["sd_v_h_kmh"] >= SD_MIN_KMH) & (df["inserted_main"] >= INSERTED_MIN))


def point_means(df: pd.DataFrame) -> pd.DataFrame:
    """Seed means per (group, demand, green share); ``stationary`` becomes the share of
    seeds that passed, ``seeds`` the count; ``qualifies`` per mean point."""
    keys = [*GROUP, "demand_veh_h", "green_share"]
    num = df.select_dtypes("number").columns.difference(keys)
    out = df.groupby(keys)[list(num)].mean()
    out["seeds"] = df.groupby(keys).size()
    out = out.reset_index()
    return out.assign(qualifies=qualifies(out))


def largest_group(df: pd.DataFrame) -> tuple[pd.DataFrame, str]:
    """The point means of the largest group of runs, and its description."""
    df = with_av_share(df)
    (step, sigma, warm, app, av), sub = max(point_means(df).groupby(GROUP),
                                            key=lambda kv: len(kv[1]))
    return sub, (f"sigma {sigma:g}, step {step:g} s\nwarm-up {warm:g} s, buffer {app:g} m, "
                 f"AV share {av:.2f}")


def with_av_share(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` with ``av_share`` filled (rows of older tables lack it) and rounded."""
    share = df["av_share"] if "av_share" in df else pd.Series(index=df.index, dtype=float)
    return df.assign(av_share=share.fillna(AV_SHARE).round(3))


def read_map(path: Path) -> pd.DataFrame:
    """An earlier ``map.csv`` (or the table of this study under another name)."""
    if not Path(path).is_file():
        raise StudyError(f"--from = {str(path)!r} is not a file; allowed: a map.csv of "
                         f"arzsumo study {NAME}")
    df = pd.read_csv(path)
    missing = [c for c in ("demand_veh_h", "green_share", "stationary", "lambda4_kmh",
                           "sd_v_h_kmh", "inserted_main") if c not in df]
    if missing:
        raise StudyError(f"--from = {str(path)!r} lacks the columns {', '.join(missing)}")
    return df


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The approach study's options."""
    parser.add_argument("--demands", type=number_list, default=[4400, 4800, 5200, 5664, 6000],
                        help="mainline demands HV + AV, veh/h (default: 4400,4800,5200,"
                             "5664,6000)")
    parser.add_argument("--greens", type=number_list, default=[0.3, 0.5, 0.7, 0.9],
                        help="nominal green shares (default: 0.3,0.5,0.7,0.9)")
    parser.add_argument("--sigmas", type=number_list, default=[0.5],
                        help="Krauss sigma of the HVs (default: 0.5)")
    add_runs(parser, seeds="1")
    parser.add_argument("--approach", type=positive_float, default=1500.0,
                        help="buffer length before x = 0, m")
    parser.add_argument("--empty-start", action="store_true",
                        help="start with an empty section (default: a congested one)")
    parser.add_argument("--warmup", type=positive_float, default=150.0, help="s not measured")
    parser.add_argument("--measured", type=positive_float, default=450.0, help="s measured")
    parser.add_argument("--step", type=positive_float, default=0.1, help="SUMO step, s")
    parser.add_argument("--av-share", type=fraction, default=AV_SHARE,
                        help="AV share of the mainline demand (default: 0.275)")
    parser.add_argument("--from", dest="source", type=Path, metavar="CSV",
                        help="draw the map of this table instead of running SUMO")
    add_output(parser, NAME, PAGE)


def run(args: argparse.Namespace) -> int:
    """Run the missing points (or read ``--from``), write the table and the map."""
    runs = design(args.demands, args.greens, args.sigmas, args.seeds, args.approach,
                  args.warmup, args.measured, args.step, not args.empty_start, args.av_share)
    if args.list:
        return print_list([r.run_id for r in runs],
                          None if args.source is None else ("--from", args.source))
    with resumable_dir(args.out, f"study-{NAME}") as out:
        if args.source is not None:
            df = read_map(args.source)
        else:
            df = pd.DataFrame(run_design(runs, run_point, out, workers=args.workers,
                                         scheduler=args.scheduler, progress=not args.quiet,
                                         label=NAME))
        files = [write_csv(df, out / "map.csv", "%.5g")]
        sub, tag = largest_group(df)
        if plots_wanted(args):
            from arzsumo.outputs.study_figures import write_approach_map

            files.append(write_approach_map(sub, with_av_share(df), tag, out / "map.png",
                                            SD_MIN_KMH, INSERTED_MIN))
        else:
            remove_stale_figures(out / "map.png")
        good = sub[sub["qualifies"]]
        text = (f"{len(df)} runs; {len(good)} of {len(sub)} points of the largest group "
                "qualify (stationary, congested, stop-and-go, inserted): "
                + (", ".join(f"{r.demand_veh_h:.0f} veh/h at green {r.green_share:g}"
                             for r in good.itertuples()) or "none"))
        if args.docs is not None:
            body = (f"{text} (`arzsumo study {NAME}`). Table: [{PAGE}.csv]({PAGE}/{PAGE}.csv)."
                    + (f"\n\n![map]({PAGE}/{PAGE}.png)" if plots_wanted(args) else ""))
            publish(args.docs, PAGE, NAME, "Where SUMO holds a stationary congested section",
                    body, [(p, f"{PAGE}{p.suffix}") for p in files])
    print(text)
    return 0
