"""Is the ablation's `meter` gain feedback, or a ramp held at its least release rate?
(``arzsumo study held-ramp``).

In the ablation's ``meter`` step (one vehicle per green, on the default's controller
side) the PDE laws lower the network time loss, and they spend much of the window at the
upper bound of U, where the meter releases at ``release_rate_min``. This study evaluates
the open loop of the same scenario with the nominal release rate set to that bound (a
fixed, restrictive meter: no feedback, held from t = 0, the warm-up included) on the
same seeds, and pairs every run set of the ``meter`` step (its open loop and both laws)
against it. Because the held meter also holds during the warm-up, this compares two
policies over the same window; it does not separate feedback from holding within it.

The ``meter`` step is read from ``--ablation DIR`` (``arzsumo study ablation --steps
identified,meter``); the held ramp's evaluation goes to ``OUT/held``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.evaluation.report import MEASURES as EVALUATION_MEASURES
from arzsumo.evaluation.report import Measure
from arzsumo.io import dump_toml
from arzsumo.outdir import resumable_dir
from arzsumo.sweep.evaluate import BASELINE, run_evaluation
from arzsumo.sweep.worker import FINISHED
from arzsumo_studies import checks
from arzsumo_studies.ablation import study as ablation
from arzsumo_studies.common import (
    EXIT_SOME_FAILED,
    RESULTS_DIR,
    StudyError,
    seed_text,
)
from arzsumo_studies.outputs.pages import publish, write_text
from arzsumo_studies.paired import paired_cell, seed_values

NAME = "held-ramp"
#: the results page this study keeps a block of (the ablation's)
PAGE = "control_in_sumo"
#: the step compared, and its run sets: (label, controller)
STEP = "meter"
SETS = (("open loop, nominal rate", BASELINE), ("backstepping", "backstepping"),
        ("ETC", "etc"))
#: the measures compared (evaluation keys); max_ramp_queue is not an evaluation measure
KEYS = ("network.time_loss_s.total", "network.time_loss_s.mainline",
        "network.time_loss_s.ramp", "network.throughput_veh_h.section_outlet",
        "section.speed_spread_kmh.h", "section.speed_spread_kmh.a")
MAX_QUEUE = Measure("max_ramp_queue", "max ramp queue", "veh")
#: the release rate of the held ramp when the scenario does not name its least one, veh/h
RELEASE_MIN_VEH_H = 240.0


def measures() -> list[Measure]:
    """The compared measures, with the evaluation's labels, units and scales."""
    return [next(m for m in EVALUATION_MEASURES if m.key == k) for k in KEYS] + [MAX_QUEUE]


def held_scenario() -> dict:
    """The ``meter`` step's scenario with the nominal release rate at its lower bound."""
    data, _ = ablation.step_scenario(STEP)
    low = data["sumo"].get("release_rate_min_veh_h", RELEASE_MIN_VEH_H)
    data["sumo"]["release_rate_veh_h"] = low
    data["name"] = "ablation-held-ramp"
    return data


def values(runs: pd.DataFrame, controller: str, m: Measure, seeds: list[int]) -> np.ndarray:
    """``controller``'s measure ``m`` on ``seeds`` from a sweep table (NaN where missing)."""
    return seed_values(runs, m, controller, seeds)


def report(meter: pd.DataFrame, held: pd.DataFrame, seeds: list[int]) -> str:
    """Markdown: per measure, each run set minus the held-ramp open loop, paired by seed
    (mean [95 % t], and in brackets the seeds lower / higher than the held ramp)."""
    lines = ["| measure | held ramp (mean) | " + " | ".join(f"{n} minus held" for n, _ in SETS)
             + " |", "|---" * (2 + len(SETS)) + "|"]
    for m in measures():
        base = values(held, BASELINE, m, seeds)
        cells = [paired_cell(values(meter, ctrl, m, seeds), base, bracket_counts=True)
                 for _, ctrl in SETS]
        mean = f"{np.nanmean(base):.4g}" if np.isfinite(base).any() else ""
        lines.append(f"| {m.label} ({m.unit}) | {mean} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


@dataclass(frozen=True)
class HeldRampOptions(checks.Shared):
    """What the held-ramp study runs and reads, and where it writes.

    Parameters
    ----------
    ablation : Path
        The ablation directory holding the ``meter`` step.
    seeds : tuple of int
        SUMO seeds of the held ramp's open loop, paired with the step's.
    report : bool
        Run nothing: the table from the evaluations already there.
    plots : bool
        Draw the held ramp's evaluation figures.

    ``out``, ``docs``, ``workers``, ``scheduler``: as every study's
    (:data:`~arzsumo_studies.common.SHARED_FIELDS`).
    """

    ablation: Path = RESULTS_DIR / ablation.NAME
    seeds: tuple[int, ...] = tuple(range(1, 11))
    report: bool = False
    out: Path = RESULTS_DIR / NAME
    plots: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        checks.seeds(self.seeds)


@dataclass(frozen=True)
class HeldRampResult:
    """The study's outcome: the exit ``code`` (0; 4 when a held-ramp run did not
    finish), the paired table's markdown ``text`` and the ``files`` written."""

    code: int
    text: str
    files: tuple[Path, ...]


def design(opts: HeldRampOptions) -> list[str]:
    """The study's one evaluation: the held ramp's open loop on the seeds."""
    return [f"held: {BASELINE} on seeds {seed_text(list(opts.seeds))}"]


def run_held_ramp(opts: HeldRampOptions, *, progress: bool = True) -> HeldRampResult:
    """Evaluate the held ramp (resumable) and pair the meter step against it.

    Parameters
    ----------
    opts : HeldRampOptions
        The study's options.
    progress : bool, optional
        Show a progress bar while the held ramp runs.

    Returns
    -------
    HeldRampResult
        The exit code, the table and the files written (``held.toml``,
        ``held_comparison.md`` and the held ramp's evaluation in ``opts.out``).
    """
    seeds = list(opts.seeds)
    meter_table = Path(opts.ablation) / STEP / "summaries.parquet"
    if not meter_table.is_file():
        raise StudyError(f"--ablation = {str(opts.ablation)!r} has no finished {STEP!r} step; "
                         "allowed: the --out of arzsumo study ablation --steps "
                         f"identified,{STEP}")
    ok = True
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        path = write_text(dump_toml(held_scenario()), out / "held.toml")
        if not opts.report:
            res = run_evaluation(path, [BASELINE], seeds, out=out / "held",
                                 workers=opts.workers, scheduler=opts.scheduler,
                                 progress=progress, plots=opts.plots)
            ok = res.sweep is None or bool(res.sweep.table["status"].isin(FINISHED).all())
        held = out / "held" / "summaries.parquet"
        if not held.is_file():
            raise StudyError(f"--out = {str(opts.out)!r} has no held-ramp evaluation yet; "
                             "allowed: a run without --report first")
        text = report(pd.read_parquet(meter_table), pd.read_parquet(held), seeds)
        files = [write_text(text, out / "held_comparison.md"), (path, "steps/held.toml")]
        files += [(out / "held" / f"evaluation{x}", f"held{x}") for x in (".csv", ".md")
                  if (out / "held" / f"evaluation{x}").is_file()]
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "Control in SUMO",
                    f"The `meter` step against the held ramp, seeds {seed_text(seeds)}, "
                    f"paired (`arzsumo study {NAME}`); the held ramp's evaluation "
                    f"[held.md]({PAGE}/held.md), its scenario "
                    f"[steps/held.toml]({PAGE}/steps/held.toml).\n\n{text}", files)
    return HeldRampResult(0 if ok else EXIT_SOME_FAILED, text,
                          tuple(f if isinstance(f, Path) else f[0] for f in files))
