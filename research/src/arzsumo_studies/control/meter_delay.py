"""The meter's dead time on the default, read off paired runs (``arzsumo study
meter-delay``).

The controllers of a seed share one warm-up, so up to the start of control their runs are
the same run, and after it SUMO stays bit-identical across them for as long as nothing
the meter did has reached a vehicle. A controller that commands another release rate than
the open loop (the held meter at once, ALINEA at the end of its first period) makes the
two runs part at the meter; they part at the section's outflow x = L, where the PDE laws'
U acts (section 2, ``eq:bc``), only when that change has travelled there. The gap between
the two moments is the meter's transport time, measured per seed without noise: no fit,
no step response to average.

Read from a control study's ``--out`` (``periods.parquet`` of each run, one row per 1 s
control period): per seed and controller, the first period whose release rate differs
from the open loop's (the command), the first whose running light differs (the plan),
and the first whose mainline outflow at x = L (HV + AV) differs (the effect). This is the
dead time the predictor of ``[actuation] delay_compensation_s`` should cover.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.errors import require
from arzsumo.outdir import resumable_dir
from arzsumo_studies import checks
from arzsumo_studies.common import RESULTS_DIR, StudyError, seed_text
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv, write_text

log = logging.getLogger(__name__)

NAME = "meter-delay"
#: the results page this study keeps a block of
PAGE = "control_default"
#: the controllers read against the open loop: each changes the release rate
PAIRED = ("held", "alinea", "pi-alinea")
#: the events of a paired run: name -> the per-period columns compared
EVENTS = {"command": ("release_rate",), "light": ("green_running",),
          "outflow": ("outflow_h", "outflow_a")}


def first_difference(a: np.ndarray, b: np.ndarray) -> int | None:
    """Index of the first row where ``a`` and ``b`` (arrays of equal width) differ, over
    their common length; None when they agree throughout. Exact: paired runs that have
    not parted agree to the last bit."""
    n = min(len(a), len(b))
    a2 = np.asarray(a, float)[:n].reshape(n, -1)
    b2 = np.asarray(b, float)[:n].reshape(n, -1)
    differs = np.flatnonzero(np.any(a2 != b2, axis=1))
    return int(differs[0]) if differs.size else None


def paired_events(run: pd.DataFrame, open_loop: pd.DataFrame) -> dict[str, float]:
    """The time (s from the start of control, the end of the period) at which ``run``
    first differs from ``open_loop`` in each of :data:`EVENTS`, NaN when it never does,
    the dead time from command to outflow and the transport from light to outflow, s."""
    times: dict[str, float] = {}
    for event, cols in EVENTS.items():
        i = first_difference(run[list(cols)].to_numpy(), open_loop[list(cols)].to_numpy())
        times[f"{event}_s"] = float("nan") if i is None else float(run["t_s"].iloc[i]) + 1.0
    times["dead_time_s"] = times["outflow_s"] - times["command_s"]
    times["light_to_outflow_s"] = times["outflow_s"] - times["light_s"]
    return times


def _periods_files(outs: list[Path], experiment: str) -> dict[tuple[str, int], Path]:
    """(controller, seed) -> its ``periods.parquet`` in the first of ``outs`` that has it
    (a study's runs may be spread over several ``--out`` directories)."""
    found: dict[tuple[str, int], Path] = {}
    for out in outs:
        for path in sorted((out / experiment / "runs").glob("controller=*,seed=*/periods.parquet")):
            ctrl, seed = (part.split("=")[1] for part in path.parent.name.split(","))
            found.setdefault((ctrl, int(seed)), path)
    return found


def delay_rows(outs: list[Path], experiment: str, controllers: tuple[str, ...]
               ) -> pd.DataFrame:
    """Every seed of ``OUT/experiment`` (over the directories ``outs``) with the open loop
    and a controller of ``controllers``: one row per (controller, seed) of
    :func:`paired_events`."""
    files = _periods_files(outs, experiment)
    rows: list[dict[str, Any]] = []
    for ctrl in controllers:
        for seed in sorted(s for c, s in files if c == ctrl and ("open", s) in files):
            rows.append({"controller": ctrl, "seed": seed,
                         **paired_events(pd.read_parquet(files[ctrl, seed]),
                                         pd.read_parquet(files["open", seed]))})
    if not rows:
        raise StudyError(f"--sumo {' '.join(map(str, outs))} holds no paired runs of the "
                         f"open loop and {', '.join(controllers)} in {experiment}; allowed: "
                         f"the --out of arzsumo study control")
    return pd.DataFrame(rows)


def delay_summary(rows: pd.DataFrame) -> pd.DataFrame:
    """Per controller: seeds, and the median, least and largest time of each event."""
    out = []
    for ctrl, g in rows.groupby("controller", sort=False):
        row: dict[str, Any] = {"controller": ctrl, "n": len(g)}
        for col, label in (("command_s", "command"), ("light_s", "light"),
                           ("outflow_s", "outflow"), ("dead_time_s", "dead time"),
                           ("light_to_outflow_s", "light to outflow")):
            v = g[col].dropna()
            row[f"{label} median, s"] = float(v.median()) if len(v) else float("nan")
            row[f"{label} range, s"] = (f"{v.min():g}-{v.max():g}" if len(v) else "-")
        out.append(row)
    return pd.DataFrame(out)


@dataclass(frozen=True)
class MeterDelayOptions:
    """What the meter-delay study reads and where it writes.

    Parameters
    ----------
    sumo : tuple of Path
        The ``--out`` directories of ``arzsumo study control`` whose runs are paired (a
        study's runs may be spread over several).
    experiment : str
        The experiment whose runs are paired.
    controllers : tuple of str
        The controllers read against the open loop, of :data:`PAIRED`.
    out : Path
        The study's directory.
    docs : Path, optional
        Also regenerate the study's block of ``docs/PAGE.md`` (None: no page).
    """

    sumo: tuple[Path, ...] = (RESULTS_DIR / "control",)
    experiment: str = "regulation"
    controllers: tuple[str, ...] = PAIRED
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None

    def __post_init__(self) -> None:
        require(len(self.sumo) > 0, "sumo", self.sumo, "at least one directory",
                StudyError)
        checks.all_among(self.controllers, PAIRED, "controllers")


@dataclass(frozen=True)
class MeterDelayResult:
    """The study's outcome: the paired ``events`` (one row per controller and seed, s
    from the start of control), their per-controller ``summary``, the markdown ``text``
    and the ``files`` written."""

    events: pd.DataFrame
    summary: pd.DataFrame
    text: str
    files: tuple[Path, ...]


def run_meter_delay(opts: MeterDelayOptions) -> MeterDelayResult:
    """The paired events of every seed, their summary, the page block.

    ``opts``: the study's :class:`MeterDelayOptions`.

    Returns
    -------
    MeterDelayResult
        The events, their summary and the files written (``paired_events.csv``,
        ``meter_delay.csv``, ``meter_delay.md`` in ``opts.out``).
    """
    rows = delay_rows(list(opts.sumo), opts.experiment, opts.controllers)
    table = delay_summary(rows)
    seeds = sorted(rows["seed"].unique().tolist())
    text = (f"Paired runs of `arzsumo study control` ({opts.experiment}, seeds "
            f"{seed_text(seeds)}): the first second after the start of control at which a "
            "controller's run differs from the open loop's in the commanded release rate, "
            "the running light and the mainline outflow at x = L (`arzsumo study "
            f"{NAME}`); dead time = outflow minus command; light to outflow = outflow minus "
            "light.\n\n" + markdown_table(table))
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        events = write_csv(rows, out / "paired_events.csv")
        files = [(write_csv(table, out / "meter_delay.csv"), "meter_delay.csv")]
        md = write_text(text, out / "meter_delay.md")
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "The meter's dead time, from paired runs", text,
                    files)
    return MeterDelayResult(rows, table, text, (events, files[0][0], md))
