"""What a boundary can reach, read off run directories: the share of the section's HV
speed variance, per band of periods, coherent with the inlet's flow q(0, t), the outlet's
flow q(L, t) and the law's input U(t) (:mod:`arzsumo_studies.measures.coherence`).

A run directory is what ``arzsumo run --out`` (or :meth:`arzsumo.RunResult.save`) writes:
``cells.parquet`` (SUMO's Edie cells, ``source == "micro"``), ``periods.parquet`` (the
class in- and outflows and U per control period) and ``summary.json`` (lambda_4). The
runs of one condition (a stream and a controller, over seeds) are pooled: their spectra
are averaged over every segment of every run.

* The speed field is averaged over ``block_s`` in time (empty 1 s cells are NaN in SUMO's
  cells; a block keeps the 20 s-1 min band at 5 s), its remaining gaps filled linearly in
  time per cell; a cell empty over a whole run is dropped from every run of the condition.
* The flows and U are averaged over the same blocks (veh/s).
* Each cell is aligned with its boundary by the travel time of what the boundary sends:
  from x = L upstream at lambda_4 (q(L) and U), from x = 0 downstream at the equilibrium's
  HV speed (q(0)).

SI inside: s, m, m/s, veh/s; the shares are dimensionless.

``arzsumo study reach`` (:func:`run_reach`) runs it once on conditions given as globs of
run directories and writes ``reach.csv`` (:func:`reach_table`'s rows), ``reach.md`` (the
command, then share [floor] per condition, boundary and band) and ``reach.png`` (the
coherence against x and period, a row of panels per condition) under ``--out``.
"""

from __future__ import annotations

import glob
import json
import math
import os
import re
import shlex
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.errors import require
from arzsumo.evaluation.authority import window_means
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.figures import remove_stale_figures
from arzsumo_studies.common import RESULTS_DIR, StudyError
from arzsumo_studies.measures.coherence import BoundaryShares, boundary_shares, travel_lags
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv, write_text

NAME = "reach"
#: the results page (``research/results/PAGE.md``) this study keeps a block of
PAGE = "reach"
#: the boundary series, in the table's order
BOUNDARIES = ("q0", "qL", "U")
#: the files of a run directory that :func:`read_run` reads
RUN_FILES = ("cells.parquet", "periods.parquet", "summary.json")
#: the table's leading columns (the rest of :meth:`CoherentShare.table`'s follow)
LEADING = ("condition", "boundary", "band", "share", "floor", "beyond_floor", "runs")


@dataclass(frozen=True)
class RunSeries:
    """One run's HV speed field (T, N) on blocks of ``dt`` s, the cells' centres ``x``
    (m), the boundary series (T,) by name, lambda_4 and the HV equilibrium speed (m/s)."""

    v: np.ndarray
    x: np.ndarray
    dt: float
    series: Mapping[str, np.ndarray]
    lambda_4: float
    v_star: float

    def __post_init__(self) -> None:
        require(self.v.ndim == 2 and self.v.shape[1] == self.x.size, "v", self.v.shape,
                "a (blocks, cells) field on x", StudyError)
        require(all(s.shape == (self.v.shape[0],) for s in self.series.values()), "series",
                {k: s.shape for k, s in self.series.items()}, "one value per block",
                StudyError)


def _filled(v: np.ndarray) -> np.ndarray:
    """Each column's NaN filled linearly in time (its ends held)."""
    out = v.copy()
    t = np.arange(v.shape[0])
    for j in range(v.shape[1]):
        ok = np.isfinite(v[:, j])
        if ok.any():
            out[:, j] = np.interp(t, t[ok], v[ok, j])
    return out


def read_run(path: Path, block_s: float = 5.0) -> RunSeries:
    """The HV speed field and the boundary series of the run directory ``path``."""
    cells = pd.read_parquet(path / "cells.parquet", filters=[("source", "==", "micro")])
    per = pd.read_parquet(path / "periods.parquet")
    summ = json.loads((path / "summary.json").read_text(encoding="utf-8"))
    period = float(np.median(np.diff(per["t_s"]))) if len(per) > 1 else 1.0
    # the cells at t_s are the end of the period checked at t_s - period: the row of t_s = 0
    # (the measurement control starts from) has no period of its own
    field = cells.pivot(index="t_s", columns="x_m", values="v_h")
    field = field.loc[np.isin(field.index, per["t_s"].to_numpy() + period)]
    blocks = max(1, round(block_s / period))
    n = len(field) // blocks
    with warnings.catch_warnings():    # a block of a cell that stayed empty: NaN, filled
        warnings.simplefilter("ignore", RuntimeWarning)
        v = np.nanmean(field.to_numpy()[: n * blocks].reshape(n, blocks, -1), axis=1)
    series = {"q0": per["inflow_h"] + per["inflow_a"],
              "qL": per["outflow_h"] + per["outflow_a"], "U": per["u_applied"]}
    means = {k: window_means(np.asarray(s, float), period, blocks * period)[:n]
             for k, s in series.items()}
    return RunSeries(v, field.columns.to_numpy(float), blocks * period, means,
                     float(summ["lambda_4"]), float(summ["equilibrium"]["v_h"]))


def reach(runs: Sequence[RunSeries]) -> BoundaryShares:
    """The coherent shares of the pooled runs (one condition): q(0), q(L) and U, each cell
    aligned by its travel time (module docstring)."""
    require(len(runs) >= 1, "runs", len(runs), "at least one run", StudyError)
    first = runs[0]
    seen = np.all([np.isfinite(r.v).any(axis=0) for r in runs], axis=0)
    require(seen.sum() >= 2, "cells", int(seen.sum()), "at least 2 cells seen in every run",
            StudyError)
    x, length = first.x[seen], float(first.x[-1] + first.x[0])
    fields = [_filled(r.v[:, seen]) for r in runs]
    lags = {"q0": travel_lags(x, 0.0, first.v_star),
            "qL": travel_lags(x, length, first.lambda_4),
            "U": travel_lags(x, length, first.lambda_4)}
    return boundary_shares(fields, {k: [r.series[k] for r in runs] for k in BOUNDARIES},
                           first.dt, x, lags=lags)


def shares_table(shares: Mapping[str, BoundaryShares]) -> pd.DataFrame:
    """One row per condition (the keys of ``shares``), boundary and band: the columns of
    :meth:`BoundaryShares.table` with ``condition`` first, then :data:`LEADING`'s order
    (shares and floors dimensionless, periods s)."""
    table = pd.concat([s.table().assign(condition=name) for name, s in shares.items()],
                      ignore_index=True)
    rest = [c for c in table.columns if c not in LEADING]
    return table[[*LEADING, *rest]]


def reach_table(conditions: Mapping[str, Sequence[Path]], block_s: float = 5.0
                ) -> pd.DataFrame:
    """One row per condition, boundary and band: the section's coherent share, its floor
    and the share beyond the floor, with the runs pooled (the directories of each
    condition; ``block_s``: the blocks averaged over, s)."""
    return shares_table({name: reach([read_run(Path(d), block_s) for d in dirs])
                         for name, dirs in conditions.items()})


def _seed_order(path: Path) -> tuple[float, str]:
    """Sort key of a run directory: its seed ``seed=K`` when its name has one, then its
    path (a directory without a seed after those with one)."""
    found = re.search(r"(?:^|[^A-Za-z0-9_])seed=(\d+)", path.name)
    return (int(found.group(1)) if found else math.inf, str(path))


def run_dirs(name: str, pattern: str, max_runs: int | None = None) -> tuple[Path, ...]:
    """The run directories of condition ``name``: those the glob ``pattern`` matches,
    sorted by seed (:func:`_seed_order`), the first ``max_runs`` of them (None: all).

    Raises
    ------
    StudyError
        The glob matches no directory, or one of them lacks a file of :data:`RUN_FILES`.
    Runs deadlocked before control (:func:`deadlocked_before_control`) are left out with
    a warning.
    """
    spec = f"{name}={pattern}"
    dirs = sorted((Path(p) for p in glob.glob(os.path.expanduser(pattern))
                   if Path(p).is_dir()), key=_seed_order)
    require(len(dirs) > 0, "--runs", spec,
            "a glob of run directories (as `arzsumo run --out` writes them); it matches "
            "none", StudyError)
    for d in dirs:
        missing = [f for f in RUN_FILES if not (d / f).is_file()]
        require(not missing, "--runs", spec,
                f"run directories holding {', '.join(RUN_FILES)}; {d} has no "
                f"{', '.join(missing)}", StudyError)
    stuck = [d for d in dirs if deadlocked_before_control(d)]
    if stuck:
        warnings.warn(f"{name}: {len(stuck)} run(s) left out, SUMO deadlocked before "
                      f"control: {', '.join(d.name for d in stuck)}", stacklevel=2)
    dirs = [d for d in dirs if d not in stuck]
    require(len(dirs) > 0, "--runs", spec, "a glob of run directories with at least one run "
            "that did not deadlock before control", StudyError)
    return tuple(dirs[:max_runs] if max_runs is not None else dirs)


def deadlocked_before_control(run: Path) -> bool:
    """Whether SUMO deadlocked in the run before its control window opened (its drain
    ended in a gridlock with a mainline vehicle standing since before the window): its
    field is a standstill's, not the stream's (as the studies' tables leave such seeds
    out, :func:`arzsumo_studies.paired.deadlocked_seeds`)."""
    summary = json.loads((run / "summary.json").read_text(encoding="utf-8"))
    drain = (summary.get("network_whole_demand") or {}).get("drain") or {}
    standstill = summary.get("longest_standstill_main")
    if not drain.get("gridlock") or standstill is None:
        return False
    return float(standstill) >= float(summary["horizon"]) + float(drain["duration_s"]) - 1.0


@dataclass(frozen=True)
class ReachOptions:
    """What ``arzsumo study reach`` reads and where it writes.

    Parameters
    ----------
    runs : tuple of (str, str)
        The conditions: (name, glob of its run directories), in the table's order.
    block_s : float
        The blocks the fields and series are averaged over, s.
    max_runs : int, optional
        The first this many directories of each condition, by seed (None: all).
    out : Path
        The study's directory.
    docs : Path, optional
        Also regenerate the study's block of ``docs/PAGE.md`` (None: no page).
    plots : bool
        Draw ``reach.png``.
    """

    runs: tuple[tuple[str, str], ...]
    block_s: float = 5.0
    max_runs: int | None = None
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    plots: bool = True

    def __post_init__(self) -> None:
        names = [n for n, _ in self.runs]
        require(len(names) > 0, "--runs", None, "at least one condition NAME=GLOB",
                StudyError)
        require(len(set(names)) == len(names) and all(n and g for n, g in self.runs),
                "--runs", [f"{n}={g}" for n, g in self.runs],
                "conditions NAME=GLOB of distinct, non-empty names and globs", StudyError)
        require(math.isfinite(self.block_s) and self.block_s > 0, "block_s", self.block_s,
                "a block > 0 s", StudyError)
        require(self.max_runs is None or self.max_runs >= 1, "max_runs", self.max_runs,
                "at least 1 run per condition", StudyError)

    def command(self) -> str:
        """The command line that runs the study with these options."""
        words = ["arzsumo", "study", NAME]
        for name, pattern in self.runs:
            words += ["--runs", f"{name}={pattern}"]
        words += ["--block-s", f"{self.block_s:g}"]
        if self.max_runs is not None:
            words += ["--max-runs", str(self.max_runs)]
        words += ["--out", str(self.out)]
        if not self.plots:
            words.append("--no-plots")
        return shlex.join(words)


@dataclass(frozen=True)
class ReachResult:
    """The study's outcome: each condition's ``dirs`` (the runs pooled) and ``shares``,
    the ``table`` (:func:`shares_table`), the markdown ``text`` and the ``files``
    written."""

    dirs: Mapping[str, tuple[Path, ...]]
    shares: Mapping[str, BoundaryShares]
    table: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def _cell(row: pd.Series) -> str:
    """``share [floor]`` of one row, two decimals; ``-`` for a band not resolved."""
    if not (np.isfinite(row["share"]) and np.isfinite(row["floor"])):
        return "-"
    return f"{row['share']:.2f} [{row['floor']:.2f}]"


def reach_markdown(table: pd.DataFrame, command: str) -> str:
    """The command (at the top), then a markdown table of ``table`` (:func:`shares_table`):
    one row per condition and boundary, a column ``share [floor]`` per band (its periods
    in s); shares and floors dimensionless."""
    bands = table.drop_duplicates("band")
    heads = {b: f"{b} {lo:g}-{hi:g} s" for b, lo, hi in
             zip(bands["band"], bands["period_short_s"], bands["period_long_s"], strict=True)}
    rows = []
    for (condition, boundary), g in table.groupby(["condition", "boundary"], sort=False):
        by_band = g.set_index("band")
        rows.append({"condition": condition, "boundary": boundary,
                     "runs": int(g["runs"].iloc[0]),
                     **{head: _cell(by_band.loc[b]) for b, head in heads.items()}})
    return (f"`{command}`\n\nThe share of the section's HV speed variance coherent with "
            "each boundary series (q0: the inlet's flow, qL: the outlet's flow, U: the "
            "law's input), per band of periods, the runs of a condition pooled: share "
            "[bias floor 1/n_eff]; a share at or below its floor is no evidence of "
            "coherence.\n\n" + markdown_table(pd.DataFrame(rows)))


def run_reach(opts: ReachOptions) -> ReachResult:
    """Read each condition's runs, pool them, write the table, its page and the figure.

    ``opts``: the study's :class:`ReachOptions`. Every glob is expanded and checked
    before anything is read or written.

    Returns
    -------
    ReachResult
        The shares and the files written (``reach.csv``, ``reach.md`` and, with
        ``opts.plots``, ``reach.png`` in ``opts.out``; without, an earlier
        ``reach.png`` is removed).
    """
    from arzsumo_studies.outputs.study_figures import write_reach_figure

    dirs = {name: run_dirs(name, pattern, opts.max_runs) for name, pattern in opts.runs}
    shares = {name: reach([read_run(d, opts.block_s) for d in ds])
              for name, ds in dirs.items()}
    table = shares_table(shares)
    text = reach_markdown(table, opts.command())
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        files = [write_csv(table, out / "reach.csv"), write_text(text, out / "reach.md")]
        figure = out / "reach.png"
        if opts.plots:
            files.append(write_reach_figure({n: s.results for n, s in shares.items()},
                                            figure))
        else:
            remove_stale_figures(figure)
        if opts.docs is not None:
            shown = f"\n\n![coherence against x and period]({PAGE}/{figure.name})"
            publish(opts.docs, PAGE, NAME, "What a boundary can reach",
                    text + (shown if opts.plots else ""), files[:1] + files[2:])
    return ReachResult(dirs, shares, table, text, tuple(files))
