"""Fill-then-hold demand on the approach network (``arzsumo study fill``).

Each point is one open-loop SUMO run (fixed-cycle meter at its nominal plan) of the
shipped default scenario's network with its ``approach`` buffer before x = 0. The
mainline demand is ``--fill-h`` / ``--fill-a`` veh/h from t = 0 to ``--fill`` s (above
the merge's discharge: the queue fills the section from the merge), then the hold demand
of the point (``--holds HV:AV`` veh/h) to the end. After ``--warmup`` s, ``--measured``
s are measured on ``main`` with the measures of :mod:`arzsumo_studies.sumo_map.open_loop`; a
point is ``ok`` when it is stationary, congested under the model and inserts at least
98 % of its demand. The design the shipped default was chosen from is the default's
own fill and hold (3750:850 veh/h after 4200 + 1300 veh/h for 600 s).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.units import veh_s_to_veh_h
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
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv

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


@dataclass(frozen=True)
class FillOptions(checks.Shared):
    """What the fill study runs and where it writes (SI units in the names).

    Parameters
    ----------
    holds : tuple of str
        Hold demands ``HV:AV``, veh/h (e.g. ``3750:850``).
    fill_h_veh_h, fill_a_veh_h : float
        HV and AV fill demand, veh/h.
    fill_s : float
        Fill phase, s.
    greens : tuple of float
        Nominal green shares.
    sigmas : tuple of float
        Krauss sigma of the HVs.
    seeds : tuple of int
        SUMO seeds.
    approach_m : float
        Buffer length before x = 0, m.
    warmup_s, measured_s : float
        Time not measured, then measured, s.
    step_s : float
        SUMO step, s.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    holds: tuple[str, ...] = ("3750:850",)
    fill_h_veh_h: float = 4200.0
    fill_a_veh_h: float = 1300.0
    fill_s: float = 600.0
    greens: tuple[float, ...] = (0.5,)
    sigmas: tuple[float, ...] = (0.5,)
    seeds: tuple[int, ...] = (1,)
    approach_m: float = 2500.0
    warmup_s: float = 600.0
    measured_s: float = 450.0
    step_s: float = 0.1
    out: Path = RESULTS_DIR / NAME

    def __post_init__(self) -> None:
        super().__post_init__()
        for h in self.holds:
            hold_pair(h)
        for field in ("fill_h_veh_h", "fill_a_veh_h", "fill_s"):
            checks.non_negative(getattr(self, field), field)
        for field in ("approach_m", "warmup_s", "measured_s", "step_s"):
            checks.positive(getattr(self, field), field)
        checks.numbers(self.greens, "greens")
        checks.numbers(self.sigmas, "sigmas")
        checks.seeds(self.seeds)


@dataclass(frozen=True)
class FillResult:
    """The study's outcome: the number of ``runs``, of them ``ok`` (stationary, congested,
    inserted), the ``table`` (one row per run), its markdown ``text`` and the ``files``
    written."""

    runs: int
    ok: int
    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def design(opts: FillOptions) -> list[StudyRun]:
    """The runs: hold demand x green share x sigma x seed, after the fill phase
    (``opts.fill_h_veh_h``, ``opts.fill_a_veh_h`` veh/h for ``opts.fill_s`` s)."""
    fill = (opts.fill_h_veh_h, opts.fill_a_veh_h, opts.fill_s)
    approach, step = opts.approach_m, opts.step_s
    warmup, measured = opts.warmup_s, opts.measured_s
    path = shipped_scenario(FORMER_DEFAULT)
    pairs = [hold_pair(h) for h in opts.holds]
    spec = study_spec(
        NAME, path, fixed_cycle(scenario_data(path)), seeds=list(opts.seeds),
        set={"sumo.fill_demand_h_veh_h": fill[0], "sumo.fill_demand_a_veh_h": fill[1],
             "sumo.fill_s": fill[2], "sumo.approach_length_m": approach,
             "sumo.step_length_s": step, "run.warmup_s": warmup, "sumo.horizon_s": measured},
        axis=[{"name": "hold", "values": list(opts.holds),
               "set": [{"sumo.demand_h_veh_h": h, "sumo.demand_a_veh_h": a} for h, a in pairs]},
              {"field": "sumo.green_share", "values": list(opts.greens)},
              {"field": "sumo.hv_sigma", "values": list(opts.sigmas)}])
    return design_runs(spec, {"fill_h_veh_h": fill[0], "fill_a_veh_h": fill[1],
                              "fill_s": fill[2], "approach_m": approach, "step_s": step,
                              "warmup_s": warmup, "measured_s": measured})


def run_point(run: StudyRun) -> dict[str, Any]:
    """One fill-then-hold run; its row (units in the column names)."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo_studies.sumo_map.open_loop import run_measures

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


def run_fill(opts: FillOptions, *, progress: bool = True) -> FillResult:
    """Run the missing points and write the table (and the page with ``opts.docs``).

    ``opts``: the study's :class:`FillOptions`; ``progress``: draw a progress bar.

    Returns
    -------
    FillResult
        The table (one row per run), the points that were ``ok`` and the file written
        (``fill.csv`` in ``opts.out``).
    """
    runs = design(opts)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        df = pd.DataFrame(run_design(runs, run_point, out, workers=opts.workers,
                                     scheduler=opts.scheduler, progress=progress,
                                     label=NAME))
        path = write_csv(df, out / "fill.csv", "%.5g")
        text = markdown_table(df[[c for c in SHOWN if c in df]])
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "Fill-then-hold demand in SUMO",
                    f"{len(df)} runs (`arzsumo study {NAME}`); {int(df['ok'].sum())} ok. "
                    f"Table: [{PAGE}.csv]({PAGE}/{PAGE}.csv).\n\n{text}",
                    [(path, f"{PAGE}.csv")])
    return FillResult(len(df), int(df["ok"].sum()) if "ok" in df else 0, df, text, (path,))
