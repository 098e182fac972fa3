"""The green-share -> mainline-outflow map from step responses in SUMO
(``arzsumo study meter-dynamics``).

Each run is one open-loop SUMO run of the former default scenario (lateral_files) (2.5 km approach,
fill then hold) with the plain fixed-cycle meter: the nominal plan (green share 0.5)
through the fill and warm-up (``--warmup`` s), ``--base`` s more at 0.5, then a sequence
of green-share steps (``--greens``, each held ``--hold`` s) that drive the meter directly
(:meth:`~arzsumo.sumo.meter.RampMeter.set_green_share`; a new plan takes effect at the
next cycle start). Every second, from 120 s before the warm-up's end, it records exactly:

* ``g_req``: the requested green share; ``g_run``: that of the running plan (after the
  cycle quantisation);
* ``out_h_veh``, ``out_a_veh``: vehicles that left ``main`` at x = L in the second (the
  section's mainline outflow: exact crossings);
* ``in_h_veh``, ``in_a_veh``: vehicles that entered ``main`` at x = 0;
* ``ramp_veh``: ramp vehicles that passed the meter in the second;
* ``n_main_veh``: vehicles on ``main`` at the end of the second; ``ramp_queue_veh``.

The series (``series.csv``, one row per second and seed) is fitted by
:mod:`arzsumo_studies.sumo_map.meter_fit`: ``fits.csv`` (one row per fit), ``levels.csv`` (the
static levels against the meter curve), ``tables.md`` and ``steps.png``. ``--series
CSV`` fits a series recorded earlier instead of running SUMO.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.errors import require
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo_studies import checks
from arzsumo_studies.common import (
    FORMER_DEFAULT,
    RESULTS_DIR,
    StudyError,
    fixed_cycle,
    scenario_data,
    seed_text,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.design import StudyRun, design_runs, run_design
from arzsumo_studies.outputs.pages import publish, write_csv, write_text
from arzsumo_studies.sumo_map import meter_fit

NAME = "meter-dynamics"
#: the results page this study keeps a block of
PAGE = "meter_dynamics"
#: file in --out -> its name on the results page
PUBLISHED = {"series.csv": "meter_steps_series.csv", "fits.csv": "meter_steps.csv",
             "levels.csv": "meter_levels.csv", "tables.md": "meter_tables.md",
             "steps.png": "meter_steps.png"}
COLUMNS = ["seed", "t_s", "g_req", "g_run", "out_h_veh", "out_a_veh", "in_h_veh",
           "in_a_veh", "ramp_veh", "n_main_veh", "ramp_queue_veh"]
GREENS = (0.2, 0.5, 0.8, 0.5, 0.2, 0.5, 0.8, 0.5)
#: s recorded before the end of the warm-up
LEAD_S = 120.0


def schedule(warmup: float, base: float, greens: list[float], hold: float
             ) -> list[tuple[float, float]]:
    """(start s, green share) of each segment: 0.5 from 0, then the steps."""
    out = [(0.0, 0.5)]
    t = warmup + base
    for g in greens:
        out.append((t, g))
        t += hold
    return out


@dataclass(frozen=True)
class MeterDynamicsOptions(checks.Shared):
    """What the meter-dynamics study runs (or reads), fits and where it writes (SI: s).

    Parameters
    ----------
    seeds : tuple of int
        SUMO seeds, one run each.
    warmup_s : float
        Fill and warm-up at green share 0.5, s.
    base_s : float
        s more at 0.5 before the steps.
    greens : tuple of float
        The green shares of the steps, each in [0, 1] (the steps drive the meter
        directly, past the scenario's green-share bounds).
    hold_s : float
        s per step.
    pre_s : float
        s before each change in its fit.
    settled_s : float
        Last s of each hold averaged for the static levels.
    series : Path, optional
        Fit this series (a ``series.csv`` of this study) instead of running SUMO.
    plots : bool
        Draw the steps' figure.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    seeds: tuple[int, ...] = (1, 2, 3)
    warmup_s: float = 600.0
    base_s: float = 60.0
    greens: tuple[float, ...] = GREENS
    hold_s: float = 102.0
    pre_s: float = 60.0
    settled_s: float = 60.0
    series: Path | None = None
    out: Path = RESULTS_DIR / NAME
    plots: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)
        for field in ("warmup_s", "base_s", "hold_s", "pre_s", "settled_s"):
            checks.positive(getattr(self, field), field)
        require(len(self.greens) > 0 and all(0.0 <= g <= 1.0 for g in self.greens),
                "greens", self.greens, "numbers in [0, 1], at least one", StudyError)


@dataclass(frozen=True)
class MeterDynamicsResult:
    """The study's outcome: the per-second ``series`` (one row per second and seed), the
    fits' markdown ``text`` and the ``files`` written."""

    series: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def design(opts: MeterDynamicsOptions) -> list[StudyRun]:
    """One run per seed: the default (fixed cycle), 1 s periods, the warm-up and steps."""
    path = shipped_scenario(FORMER_DEFAULT)
    greens = tuple(opts.greens)
    spec = study_spec(NAME, path, fixed_cycle(scenario_data(path)), seeds=list(opts.seeds),
                      set={"sumo.control_period_s": 1.0, "run.warmup_s": opts.warmup_s,
                           "sumo.horizon_s": opts.base_s + opts.hold_s * len(greens)})
    return design_runs(spec, {"base_s": opts.base_s, "greens": list(greens),
                              "hold_s": opts.hold_s})


def run_steps(run: StudyRun) -> dict[str, Any]:
    """One open-loop run with the green-share steps: its per-second rows and report."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.sumo.network import MAIN
    from arzsumo.sumo.period_reads import OpenLoopPeriod, OpenLoopReads
    from arzsumo.sumo.plant import SumoPlant
    from arzsumo.sumo.simulation import open_simulation

    t0 = time.perf_counter()
    sc = scenario_from_dict(run.scenario, run.source)
    warmup, opt = sc.run.warmup, run.options
    cfg = sc.sumo.with_(horizon=warmup + sc.sumo.horizon)
    plan = schedule(warmup, opt["base_s"], opt["greens"], opt["hold_s"])
    rows: list[dict[str, Any]] = []

    def keep(p: OpenLoopPeriod) -> None:
        m = p.measurement
        if m is None or m.t <= warmup - LEAD_S + 1e-9:
            return
        c = m.cells
        rows.append({"seed": cfg.seed, "t_s": round(c.t, 3),
                     "g_req": plan[0][1] if p.plan is None else p.plan,
                     "g_run": p.meter.green_share,
                     "out_h_veh": round(c.outflow_h * c.window),
                     "out_a_veh": round(c.outflow_a * c.window),
                     "in_h_veh": round(c.inflow_h * c.window),
                     "in_a_veh": round(c.inflow_a * c.window), "ramp_veh": p.ramp_passed,
                     "n_main_veh": p.vehicles[MAIN], "ramp_queue_veh": m.ramp_queue})

    with open_simulation(sc.params, cfg) as sim:
        plant = SumoPlant(sim, sc.params.length, cfg)   # the fixed cycle: cfg's mode
        # each plan asked half a cycle early: it runs from ``start``, the next cycle start
        plant.run_open_loop(on_period=keep, until=cfg.horizon, green_shares=True,
                            plans=[(start - cfg.meter_cycle / 2, g) for start, g in plan],
                            reads=OpenLoopReads(edges=(MAIN,), ramp_passed=True))
    rep = sim.report
    return {"series": rows, "info": {"seed": cfg.seed, "wall_s": time.perf_counter() - t0,
                                     "collisions": rep.collisions,
                                     "emergency_stops": rep.emergency_stops,
                                     "inserted_main": rep.delivered_main}}


def read_series(path: Path) -> pd.DataFrame:
    """A series recorded earlier (the columns of :data:`COLUMNS`)."""
    if not Path(path).is_file():
        raise StudyError(f"--series = {str(path)!r} is not a file; allowed: a series.csv of "
                         f"arzsumo study {NAME}")
    df = pd.read_csv(path)
    missing = [c for c in COLUMNS if c not in df]
    if missing:
        raise StudyError(f"--series = {str(path)!r} lacks the columns {', '.join(missing)}")
    return df[COLUMNS]


def analyse(series: pd.DataFrame, out: Path, pre: float, settled: float, plots: bool
            ) -> tuple[list[Path], str]:
    """Fit and write ``fits.csv``, ``levels.csv``, ``tables.md`` (and ``steps.png``, else
    one of an earlier call is removed); return the files and the tables' text."""
    from arzsumo.sumo.green_share import DEFAULT_CURVE

    data = meter_fit.by_seed(series)
    rows = meter_fit.fits(data, "y", pre) + meter_fit.fits(data, "ramp", pre, detail=False)
    levels = meter_fit.levels_table(meter_fit.static_levels(data, settled), DEFAULT_CURVE)
    text = meter_fit.tables(rows, levels)
    files = [write_csv(pd.DataFrame(rows, columns=meter_fit.FIT_FIELDS), out / "fits.csv",
                       "%.5g"), write_csv(levels, out / "levels.csv"),
             write_text(text, out / "tables.md")]
    if plots:
        from arzsumo_studies.outputs.study_figures import write_meter_steps_figure

        models = {r["seed"]: meter_fit.staircase_model(data[r["seed"]], r, pre) for r in rows
                  if r["signal"] == "y" and r["scope"] == "staircase"}
        files.append(write_meter_steps_figure(data, models, meter_fit.ensembles(data, rows),
                                              out / "steps.png"))
    else:
        remove_stale_figures(out / "steps.png")
    return files, text


def run_meter_dynamics(opts: MeterDynamicsOptions, *, progress: bool = True
                       ) -> MeterDynamicsResult:
    """Run the steps (or read ``opts.series``), fit, write (and publish with
    ``opts.docs``).

    ``opts``: the study's :class:`MeterDynamicsOptions`; ``progress``: draw a progress bar.

    Returns
    -------
    MeterDynamicsResult
        The series, the fits' tables and the files written (``series.csv``,
        ``fits.csv``, ``levels.csv``, ``tables.md``, ``steps.png`` in ``opts.out``).
    """
    runs = design(opts)
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        if opts.series is not None:
            series = read_series(opts.series)
        else:
            done = run_design(runs, run_steps, out, workers=opts.workers,
                              scheduler=opts.scheduler, progress=progress, label=NAME)
            series = pd.DataFrame([r for d in done for r in d["series"]], columns=COLUMNS)
        files = [write_csv(series, out / "series.csv")]
        more, text = analyse(series, out, opts.pre_s, opts.settled_s, opts.plots)
        files += more
        if opts.docs is not None:
            seeds = sorted(series["seed"].unique().tolist())
            body = (f"Green-share steps on seeds {seed_text(seeds)} (`arzsumo study {NAME}`): "
                    f"[series]({PAGE}/meter_steps_series.csv), [fits]({PAGE}/meter_steps.csv),"
                    f" [levels]({PAGE}/meter_levels.csv).\n\n{text}"
                    + (f"\n\n![steps]({PAGE}/meter_steps.png)" if opts.plots else ""))
            publish(opts.docs, PAGE, NAME, "Meter dynamics in SUMO", body,
                    [(p, PUBLISHED[p.name]) for p in files])
    return MeterDynamicsResult(series, text, tuple(files))
