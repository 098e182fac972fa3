"""Where SUMO holds a stationary congested section: the open loop over mainline demand x
green share (``arzsumo study approach``).

Each point is one open-loop SUMO run (fixed-cycle meter at its nominal plan, no fill
phase) of the former default scenario (lateral_files)'s network, with its ``approach`` buffer edge
before x = 0: mainline demand (HV + AV at ``--av-share``) x nominal green share x Krauss
sigma x seed, started from a congested section (``--empty-start``: from an empty one).
After ``--warmup`` s, ``--measured`` s are measured on ``main``
(:mod:`arzsumo_studies.sumo_map.open_loop`: stationarity, densities, speeds, speed sd, flows,
insertion, the approach queue, lambda_4 under the scenario's model).

``map.csv`` has one row per run, ``map.png`` the map: the demand x green-share grid of
the largest group of runs (same step, sigma, warm-up, buffer length and AV share; seeds
averaged per point), and every run's trend against stop-and-go and insertion against
the buffer queue. A point *qualifies* (:func:`qualifies`) when it is stationary,
congested under the model, shows stop-and-go and inserts its demand. ``--from CSV``
draws the map of an earlier table instead of running SUMO.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    StudyError,
    fixed_cycle,
    scenario_data,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.design import StudyRun, design_runs, run_design
from arzsumo_studies.outputs.pages import publish, write_csv

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


@dataclass(frozen=True)
class ApproachOptions(checks.Shared):
    """What the approach study runs (or reads) and where it writes (SI units in the
    names).

    Parameters
    ----------
    demands : tuple of float
        Mainline demands HV + AV, veh/h.
    greens : tuple of float
        Nominal green shares.
    sigmas : tuple of float
        Krauss sigma of the HVs.
    seeds : tuple of int
        SUMO seeds.
    approach_m : float
        Buffer length before x = 0, m.
    initial : bool
        Start with a congested section (False: an empty one).
    warmup_s, measured_s : float
        Time not measured, then measured, s.
    step_s : float
        SUMO step, s.
    av_share : float
        AV share of the mainline demand, in [0, 1].
    source : Path, optional
        Draw the map of this table instead of running SUMO.
    plots : bool
        Draw the map.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    demands: tuple[float, ...] = (4400.0, 4800.0, 5200.0, 5664.0, 6000.0)
    greens: tuple[float, ...] = (0.3, 0.5, 0.7, 0.9)
    sigmas: tuple[float, ...] = (0.5,)
    seeds: tuple[int, ...] = (1,)
    approach_m: float = 1500.0
    initial: bool = True
    warmup_s: float = 150.0
    measured_s: float = 450.0
    step_s: float = 0.1
    av_share: float = AV_SHARE
    source: Path | None = None
    out: Path = RESULTS_DIR / NAME
    plots: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        for field in ("demands", "greens", "sigmas"):
            checks.numbers(getattr(self, field), field)
        checks.seeds(self.seeds)
        for field in ("approach_m", "warmup_s", "measured_s", "step_s"):
            checks.positive(getattr(self, field), field)
        checks.fraction(self.av_share, "av_share")


@dataclass(frozen=True)
class ApproachResult:
    """The study's outcome: the ``table`` (one row per run), the point means of its
    largest group (``points``), how many of them ``qualify``, the summary ``text`` and
    the ``files`` written."""

    table: pd.DataFrame
    points: pd.DataFrame
    qualify: int
    text: str
    files: tuple[Path, ...]


def design(opts: ApproachOptions) -> list[StudyRun]:
    """The runs of the map: demand x green share x sigma x seed."""
    path = shipped_scenario(FORMER_DEFAULT)
    demands, av_share = list(opts.demands), opts.av_share
    sets = [{"sumo.demand_h_veh_h": d * (1 - av_share), "sumo.demand_a_veh_h": d * av_share}
            for d in demands]
    spec = study_spec(
        NAME, path, fixed_cycle(scenario_data(path)), seeds=list(opts.seeds),
        set={"sumo.approach_length_m": opts.approach_m, "sumo.step_length_s": opts.step_s,
             "sumo.fill_s": 0.0, "run.warmup_s": opts.warmup_s,
             "sumo.horizon_s": opts.measured_s},
        axis=[{"name": "demand_veh_h", "values": demands, "set": sets},
              {"field": "sumo.green_share", "values": list(opts.greens)},
              {"field": "sumo.hv_sigma", "values": list(opts.sigmas)}])
    return design_runs(spec, {"initial": opts.initial, "av_share": av_share,
                              "approach_m": opts.approach_m, "step_s": opts.step_s,
                              "warmup_s": opts.warmup_s, "measured_s": opts.measured_s})


def run_point(run: StudyRun) -> dict[str, Any]:
    """One open-loop run of the map; its row (units in the column names)."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo_studies.sumo_map.open_loop import initial_vehicles, run_measures

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


def run_approach(opts: ApproachOptions, *, progress: bool = True) -> ApproachResult:
    """Run the missing points (or read ``opts.source``), write the table and the map.

    ``opts``: the study's :class:`ApproachOptions`; ``progress``: draw a progress bar.

    Returns
    -------
    ApproachResult
        The table, the largest group's point means and the files written (``map.csv``,
        ``map.png`` in ``opts.out``).
    """
    runs = design(opts)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        if opts.source is not None:
            df = read_map(opts.source)
        else:
            df = pd.DataFrame(run_design(runs, run_point, out, workers=opts.workers,
                                         scheduler=opts.scheduler, progress=progress,
                                         label=NAME))
        files = [write_csv(df, out / "map.csv", "%.5g")]
        sub, tag = largest_group(df)
        if opts.plots:
            from arzsumo_studies.outputs.study_figures import write_approach_map

            files.append(write_approach_map(sub, with_av_share(df), tag, out / "map.png",
                                            SD_MIN_KMH, INSERTED_MIN))
        else:
            remove_stale_figures(out / "map.png")
        good = sub[sub["qualifies"]]
        text = (f"{len(df)} runs; {len(good)} of {len(sub)} points of the largest group "
                "qualify (stationary, congested, stop-and-go, inserted): "
                + (", ".join(f"{r.demand_veh_h:.0f} veh/h at green {r.green_share:g}"
                             for r in good.itertuples()) or "none"))
        if opts.docs is not None:
            body = (f"{text} (`arzsumo study {NAME}`). Table: [{PAGE}.csv]({PAGE}/{PAGE}.csv)."
                    + (f"\n\n![map]({PAGE}/{PAGE}.png)" if opts.plots else ""))
            publish(opts.docs, PAGE, NAME, "Where SUMO holds a stationary congested section",
                    body, [(p, f"{PAGE}{p.suffix}") for p in files])
    return ApproachResult(df, sub, len(good), text, tuple(files))
