"""The paper's penetration claim in SUMO (``arzsumo study penetration``).

The paper (section 5, table diffpene) finds that more AVs at equal inflow make the ETC
trigger less and leave the meter alone longer (44 -> 53 %: 245 -> 152 triggers, release
time 206 -> 299 s). The study runs the ETC on the default over the AV share with the
shipped sweeps (:data:`SWEEPS`, through the sweep engine; a record store with
``--records`` carries them across machines):

- ``penetration_sumo``: the ETC as the control study runs it;
- ``penetration_deadband_sumo``: its trigger given the noise dead band of the control
  ablation (without it the ETC fires at nearly every check at every share, so its
  triggers cannot fall).

With ``--share-models DIR`` (the output of ``arzsumo study share-models``) the study runs
instead one sweep built in code, ``penetration_share_models``: the ETC on each share's
own scenario (the demand mapped to that share's discharge, the model identified there,
the ETC designed for it; :func:`share_sweep`), with the wave measures beside the claim's.

Each measure's trend is read per seed, the seed being paired across shares: the
least-squares slope of the measure against the share on that seed, in units per 10
percentage points, then the mean slope over seeds with its Student t and BCa bootstrap
95 % intervals (:mod:`arzsumo.evaluation.stats`). The claim holds when the triggers'
interval lies below zero and the release time's above (:func:`verdict`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.evaluation.stats import MeanCI, bootstrap_mean_ci, mean_ci
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo.resources import shipped_sweeps_dir
from arzsumo.sweep.evaluate import BASELINE
from arzsumo.sweep.spec import SweepSpec, load_sweep
from arzsumo.sweep.worker import FINISHED
from arzsumo_studies import checks
from arzsumo_studies.common import RESULTS_DIR, StudyError
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv, write_text
from arzsumo_studies.outputs.penetration import PENETRATION_FIGURE
from arzsumo_studies.recorded import check_store
from arzsumo_studies.records import copy_records, records_table

log = logging.getLogger(__name__)

NAME, PAGE = "penetration", "control_default"
#: the shipped sweeps the study runs: name -> what its ETC is
SWEEPS = {"penetration_sumo": "ETC",
          "penetration_deadband_sumo": "ETC with the noise dead band"}
#: every sweep's title on the page (the shipped ones and ``--share-models``')
TITLES = {**SWEEPS, "penetration_share_models": "ETC designed per share, on the demand "
                                                "mapped to each share's discharge"}
#: summary key -> (label, unit) of the measures the claim is about
MEASURES = {"triggers": ("controller updates", "n"),
            "release_time": ("release time", "s"),
            "plan_changes": ("meter plan changes", "n"),
            # the premise's stationary point: a share whose queue spills past x = 0 starves
            # insertion, and its runs are no longer the congested state the law regulates
            "inserted_fraction_main": ("mainline demand inserted", "share"),
            "section.waves.h.band_power_kmh2": ("HV band power 1-10 min", "(km/h)^2"),
            "section.waves.a.band_power_kmh2": ("AV band power 1-10 min", "(km/h)^2"),
            "section.speed_oscillation_kmh.h": ("HV speed oscillation", "km/h"),
            # the premise at each share: do the stream's waves still grow upstream
            "section.waves.h.growth_per_km": ("HV wave growth upstream", "1/km"),
            # a share whose merge deadlocked is cleared by SUMO's teleport where the
            # scenario allows it; each teleport is a jolt in the section's speeds
            "teleports": ("SUMO teleports", "n")}
#: the sweep of ``--share-models``: the ETC on each share's own scenario
SHARE_SWEEP = "penetration_share_models"
SHARE = "penetration"
#: the controller axis of ``--with-open``: the law the claim is about and its baseline
CONTROLLER, LAW = "controller", "etc"
#: the slope's unit of share: 10 percentage points
PER = 0.10


def seed_slopes(table: pd.DataFrame, key: str) -> pd.Series:
    """Per seed, the least-squares slope of ``key`` against the AV share, per :data:`PER`
    of share; seeds with fewer than two shares are left out."""
    out = {}
    for seed, g in table.dropna(subset=[key]).groupby("seed"):
        x, y = g[SHARE].to_numpy(float), g[key].to_numpy(float)
        if np.unique(x).size >= 2:      # a constant measure's slope is 0, not round-off
            out[seed] = float(np.polyfit(x, y, 1)[0]) * PER if np.ptp(y) > 0 else 0.0
    return pd.Series(out, name=key, dtype=float)


def measures_in(table: pd.DataFrame) -> dict[str, tuple[str, str]]:
    """The :data:`MEASURES` a table of runs has (earlier sweeps' records lack some)."""
    return {k: v for k, v in MEASURES.items() if k in table.columns}


def finite_ci(values: np.ndarray, boot: bool = False) -> MeanCI | None:
    """The mean of ``values`` with its 95 % t (``boot``: BCa bootstrap) interval over the
    finite ones; None when there are none (a wave measure with too few places read)."""
    a = np.asarray(values, dtype=float)
    a = a[np.isfinite(a)]
    if a.size == 0:
        return None
    return bootstrap_mean_ci(a) if boot else mean_ci(a)


def level_table(table: pd.DataFrame) -> pd.DataFrame:
    """Per share and measure: mean over seeds with its 95 % t interval, and n (a measure
    no seed of a share could read is left out)."""
    rows = []
    for share, g in table.groupby(SHARE):
        for key, (label, unit) in measures_in(table).items():
            ci = finite_ci(g[key].to_numpy(float))
            if ci is not None:
                rows.append({"share": share, "measure": label, "unit": unit,
                             "mean": ci.mean, "low": ci.low, "high": ci.high, "n": ci.n})
    return pd.DataFrame(rows)


def slope_table(table: pd.DataFrame) -> pd.DataFrame:
    """Per measure: the mean per-seed slope per 10 points of share, t and BCa intervals."""
    rows = []
    for key, (label, unit) in measures_in(table).items():
        s = seed_slopes(table, key).to_numpy()
        t, boot = finite_ci(s), finite_ci(s, boot=True)
        if t is None or boot is None:
            continue
        rows.append({"measure": label, "unit": f"{unit} per 10 pt", "slope": t.mean,
                     "t_low": t.low, "t_high": t.high, "boot_low": boot.low,
                     "boot_high": boot.high, "n_seeds": t.n})
    return pd.DataFrame(rows)


def verdict(triggers: MeanCI, release: MeanCI) -> str:
    """The paper's direction (fewer triggers, longer release with more AVs): "yes" when
    both intervals lie on its side of zero, "no" when either lies on the other side or
    is exactly zero (a measure that does not move with the share at all, e.g. an ETC
    that updates once at every share), else "not resolved"."""
    if triggers.high < 0 < release.low:
        return "yes"
    if triggers.low > 0 or release.high < 0 or _exactly_zero(triggers) \
            or _exactly_zero(release):
        return "no"
    return "not resolved"


def _exactly_zero(ci: MeanCI) -> bool:
    return ci.low == ci.high == 0.0


def claim_text(table: pd.DataFrame) -> tuple[str, str]:
    """What SUMO measured of the claim on one sweep's finished runs, and the verdict."""
    slopes = {k: mean_ci(seed_slopes(table, k).to_numpy()) for k in ("triggers",
                                                                     "release_time")}
    t, r = slopes["triggers"], slopes["release_time"]
    lo, hi = table[SHARE].min(), table[SHARE].max()
    means = table.groupby(SHARE)[["triggers", "release_time"]].mean()
    return (f"{lo:.0%} -> {hi:.0%} AVs: triggers {means.triggers[lo]:.0f} -> "
            f"{means.triggers[hi]:.0f}, release {means.release_time[lo]:.0f} -> "
            f"{means.release_time[hi]:.0f} s; per 10 pt of share, triggers "
            f"{t.mean:+.3g} [{t.low:+.3g}, {t.high:+.3g}], release {r.mean:+.3g} "
            f"[{r.low:+.3g}, {r.high:+.3g}] s ({t.n} seeds); mainline demand inserted "
            f"{_inserted(table, lo):.0%} -> {_inserted(table, hi):.0%}", verdict(t, r))


def _inserted(table: pd.DataFrame, share: float) -> float:
    return float(table.loc[table[SHARE] == share, "inserted_fraction_main"].mean())


def of_controller(table: pd.DataFrame, controller: str) -> pd.DataFrame:
    """The runs of ``controller`` (every run's summary names its controller; a table
    without the column holds the ETC's runs alone)."""
    if CONTROLLER not in table.columns:
        return table if controller == LAW else table.iloc[0:0]
    return table[table[CONTROLLER] == controller]


def paired_table(table: pd.DataFrame) -> pd.DataFrame:
    """Per share and measure: the ETC minus the open loop on the same seed, mean with its
    95 % t interval, and n (empty without open-loop runs)."""
    law, base = of_controller(table, LAW), of_controller(table, BASELINE)
    if base.empty:
        return pd.DataFrame()
    law, base = law.set_index([SHARE, "seed"]), base.set_index([SHARE, "seed"])
    rows = []
    for key, (label, unit) in measures_in(table).items():
        diff = (law[key].astype(float) - base[key].astype(float)).dropna()
        for share, d in diff.groupby(level=0):
            ci = finite_ci(d.to_numpy(float))
            if ci is None:
                continue
            rows.append({"share": share, "measure": label, "unit": unit,
                         "etc_minus_open": ci.mean, "low": ci.low, "high": ci.high,
                         "n": ci.n})
    return pd.DataFrame(rows)


def report(tables: dict[str, pd.DataFrame]) -> str:
    """The study's page: per sweep the ETC's levels, slopes and the claim's verdict, and,
    where the open loop ran on the same seeds, its levels and the paired differences."""
    parts = ["The paper's claim: more AVs at equal inflow, fewer triggers and a longer "
             "release (44 -> 53 %: 245 -> 152 triggers, 206 -> 299 s). Slopes are per "
             "seed, against the share, then averaged over seeds (95 % t and BCa "
             "intervals)."]
    for name, table in tables.items():
        law = of_controller(table, LAW)
        measured, said = claim_text(law)
        parts += [f"## {TITLES[name]} (`{name}`)", f"{measured}: **{said}**",
                  markdown_table(level_table(law)), markdown_table(slope_table(law))]
        paired = paired_table(table)
        if not paired.empty:
            parts += ["The open loop on the same seeds, its levels per share, then the ETC "
                      "minus the open loop per share (paired by seed):",
                      markdown_table(level_table(of_controller(table, BASELINE))),
                      markdown_table(paired)]
    return "\n\n".join(parts) + "\n"


def _flat(data: dict) -> dict[str, object]:
    return {f"{t}.{k}": v for t, table in data.items() if isinstance(table, dict)
            for k, v in table.items()}


def share_sweep(directory: Path, seeds: list[int] | None, with_open: bool = False
                ) -> SweepSpec:
    """The ETC on each share's scenario of a ``share-models`` output ``directory``: one
    axis ``penetration`` (the shares of its ``share_models.csv``) whose values set every
    key in which a share's scenario differs from the first share's; seeds 1-10 unless
    ``seeds``; the control window only (no drain), as the shipped sweeps. ``with_open``:
    a second axis ``controller`` adds the open loop on the same seeds (its runs share
    each seed's warm-up with the ETC's)."""
    import tomllib

    from arzsumo_studies.common import study_spec

    index = directory / "share_models.csv"
    if not index.is_file():
        raise StudyError(f"--share-models = {directory} has no share_models.csv; allowed: "
                         "the --out of arzsumo study share-models")
    rows = pd.read_csv(index).sort_values("av_share")
    files = [directory / f"{p}.toml" for p in rows["point"]]
    data = [tomllib.loads(f.read_text(encoding="utf-8")) for f in files]
    base = _flat(data[0])
    sets = [{k: v for k, v in _flat(d).items() if base.get(k) != v} for d in data]
    # the controller axis is there with the ETC alone too, so that its runs keep their
    # IDs (and records) whether or not the open loop runs beside them
    controllers = (LAW, BASELINE) if with_open else (LAW,)
    axes = [{"name": SHARE, "values": [float(v) for v in rows["av_share"]], "set": sets},
            {"name": CONTROLLER, "values": list(controllers),
             "set": [{"run.controller": c} for c in controllers]}]
    return study_spec(SHARE_SWEEP, files[0], seeds=seeds or list(range(1, 11)),
                      set={"sumo.drain_max_s": 0, "run.controller": LAW}, axis=axes)


@dataclass(frozen=True)
class PenetrationOptions(checks.Shared):
    """What ``arzsumo study penetration`` runs.

    ``seeds``: SUMO seeds (None: each sweep file's own); ``records``, ``report``: the
    record store and run-nothing (as :class:`~arzsumo_studies.recorded.RecordedRuns`);
    ``share_models``: the ``--out`` of ``arzsumo study share-models`` (None: the shipped
    sweeps); ``with_open``: the open loop too, on the same seeds (with
    ``share_models``); ``out``, ``docs``, ``page``, ``plots``: where and what the study
    writes (``page``: the page under ``docs``); ``workers``, ``scheduler``,
    ``progress``: how the runs run.
    """

    seeds: tuple[int, ...] | None = None
    records: Path | None = None
    report: bool = False
    share_models: Path | None = None
    with_open: bool = False
    out: Path = RESULTS_DIR / NAME
    page: str = PAGE
    plots: bool = True
    progress: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.seeds is not None:
            checks.seeds(self.seeds)
        check_store(self.records, self.report)
        if self.with_open and self.share_models is None:
            raise StudyError("--with-open is not allowed without --share-models: the "
                             "shipped sweeps run the ETC alone")


@dataclass(frozen=True)
class PenetrationResult:
    """Per sweep its finished runs (``tables``), the page's text, and whether every run
    of every sweep finished (``complete``)."""

    tables: dict[str, pd.DataFrame]
    text: str
    complete: bool


def specs_of(opts: PenetrationOptions) -> list[SweepSpec]:
    """The sweeps the study runs."""
    seeds = None if opts.seeds is None else list(opts.seeds)
    if opts.share_models is not None:
        return [share_sweep(opts.share_models, seeds, opts.with_open)]
    return [with_seeds(load_sweep(shipped_sweeps_dir() / f"{n}.toml"), seeds)
            for n in SWEEPS]


def design(opts: PenetrationOptions) -> list[str]:
    """One line per sweep: its name and number of runs (``--list``)."""
    return [f"{spec.name}: {len(spec.runs())} runs" for spec in specs_of(opts)]


def with_seeds(spec: SweepSpec, seeds: list[int] | None) -> SweepSpec:
    """``spec`` on ``seeds`` instead of its own (unchanged when None)."""
    if seeds is None:
        return spec
    axes = tuple(replace(a, values=tuple(seeds), sets=tuple({a.field: s} for s in seeds))
                 if a.name == "seed" else a for a in spec.axes)
    return replace(spec, axes=axes)


def _finished(opts: PenetrationOptions, spec: SweepSpec, out: Path) -> pd.DataFrame:
    """The sweep's finished runs in ``out`` or the store; unless ``report`` the missing
    ones are run first."""
    from arzsumo.sweep.driver import run_sweep

    store = None if opts.records is None else opts.records / spec.name
    places = [out, *([store] if store is not None else [])]
    if not opts.report:
        with resumable_dir(out, "sweep"):
            if store is not None:
                copy_records(spec.runs(), store, out)
        try:
            run_sweep(spec, out, workers=opts.workers, scheduler=opts.scheduler,
                      progress=opts.progress, plots=False)
        finally:
            if store is not None:
                copy_records(spec.runs(), out, store)
    table = records_table(spec.runs(), *places)
    return table[table["status"].isin(FINISHED)]


def _write(tables: dict[str, pd.DataFrame], out: Path, opts: PenetrationOptions) -> str:
    """Each sweep's CSV (levels and slopes), the figure and the page; return the text."""
    files = []
    for name, table in tables.items():
        law, base = of_controller(table, LAW), of_controller(table, BASELINE)
        files.append(write_csv(pd.concat([level_table(law).assign(kind="level"),
                                          slope_table(law).assign(kind="slope"),
                                          level_table(base).assign(kind="level_open"),
                                          paired_table(table).assign(kind="paired")]),
                               out / f"{name}.csv"))
    text = report(tables)
    if opts.plots:
        from arzsumo_studies.outputs.penetration import write_penetration_figure

        drawn = {TITLES[n]: of_controller(t, LAW) for n, t in tables.items()}
        opened = {n: of_controller(t, BASELINE) for n, t in tables.items()}
        drawn |= {f"the open loop on the same seeds ({n})": t
                  for n, t in opened.items() if not t.empty}
        inflow = ("each share at its own mapped demand" if opts.share_models is not None
                  else "equal inflow")
        files.append(write_penetration_figure(out, drawn, inflow))
        text += "\n![ETC against the AV share](penetration.png)\n"
    else:
        remove_stale_figures(out / PENETRATION_FIGURE)
    write_text(text, out / "penetration.md")
    if opts.docs is not None:
        publish(opts.docs, opts.page, NAME, "The controllers in SUMO", text,
                [(f, f.name) for f in files])
    return text


def run_penetration(opts: PenetrationOptions) -> PenetrationResult:
    """Every sweep (resumable), then the levels, slopes and verdicts."""
    specs = specs_of(opts)
    if opts.report:     # refused before anything is written when there is nothing to read
        found = {s.name: _finished(opts, s, opts.out / s.name) for s in specs}
        if all(t.empty for t in found.values()):
            raise StudyError(f"--out = {opts.out} has no finished runs yet; allowed: a run "
                             "without --report, or --records with a store that holds some")
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        if not opts.report:
            found = {s.name: _finished(opts, s, out / s.name) for s in specs}
        tables = {n: t for n, t in found.items() if not t.empty}
        if not tables:
            raise StudyError(f"no run of {', '.join(found)} finished; the failures are in "
                             f"{opts.out}")
        text = _write(tables, out, opts)
    complete = all(len(found[s.name]) == len(s.runs()) for s in specs)
    return PenetrationResult(tables, text, complete or opts.report)
