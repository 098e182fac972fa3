"""How the ETC's event trigger meets the noise of the state it sees (``arzsumo study
etc-noise``).

In SUMO the designed ETC of the default may update its U at almost every check, as
continuous backstepping does, where in the noise-free twin it updates at a fraction of
them. This study puts the difference down to a number: the nonlinear twin of the scenario
(its model, its ``[design]``, its ``[twin]`` and ``[initial]`` tables), with the PDE laws
checked on the state through relative white noise of sd ``--levels`` per field, cell and
check (:class:`~arzsumo_studies.measures.state_noise.NoisyState`), on ``--seeds`` noise
seeds. Per level
and law it reports the events (updates of the held U), the noise of the law's output (the
sd of its change from one check to the next, veh/h) and the deviation norm's final ratio.

With ``--sumo DIR`` (the output of ``arzsumo study control``) it adds the same two
numbers read off SUMO's runs there (``periods.parquet``: ``u_continuous``, ``triggered``),
so SUMO's point can be read against the twin's curve: which noise level gives SUMO's
output noise, and how many events the trigger fires at that level.
"""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.engines.twin import run_twin, twin_controller
from arzsumo.evaluation.stats import mean_ci
from arzsumo.model.characteristic import linearize
from arzsumo.outdir import resumable_dir
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import load_scenario
from arzsumo.units import veh_s_to_veh_h
from arzsumo_studies import checks
from arzsumo_studies.common import (
    RESULTS_DIR,
    StudyError,
    number_list,
    seed_text,
)
from arzsumo_studies.measures.state_noise import NoisyState
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv, write_text

log = logging.getLogger(__name__)

NAME = "etc-noise"
#: the results page this study keeps a block of
PAGE = "control_default"
#: the laws compared: the ETC, the continuous law it samples, the observer-based ETC
LAWS = ("backstepping", "etc", "observer-etc")
#: relative noise sd of the fields, %
LEVELS_PCT = "0,0.01,0.03,0.1,0.3,1,2,4"


def output_noise_veh_h(u_continuous: np.ndarray) -> float:
    """The sd (veh/h) of the law's change from one check to the next (``u_continuous``
    in veh/s, one value per check): the noise the trigger has to tell from a wave."""
    u = np.asarray(u_continuous, dtype=float)
    u = u[np.isfinite(u)]
    return float(veh_s_to_veh_h(np.std(np.diff(u)))) if u.size > 2 else float("nan")


#: the scenario of a path, read once per process (every task of a study names the same one)
_scenario = functools.lru_cache(maxsize=4)(load_scenario)


def twin_row(task: tuple[Path, str, float, int]) -> dict[str, Any]:
    """One twin run: (scenario, law, noise sd in %, noise seed) -> its row."""
    path, law, level_pct, seed = task
    sc = _scenario(path)
    cfg = replace(sc.twin, controller=law)
    ctrl = NoisyState(twin_controller(cfg, linearize(sc.equilibrium)), level_pct / 100.0,
                      seed)
    run = run_twin(sc, cfg, controller=ctrl, baseline=False)
    n_checks = len(ctrl.log.t)
    return {"law": law, "noise_pct": level_pct, "seed": seed, "checks": n_checks,
            "events": run.triggers, "event_share": run.triggers / max(n_checks, 1),
            "output_noise_veh_h": output_noise_veh_h(np.asarray(ctrl.log.u_continuous)),
            "final_norm_ratio": float(run.norm[-1] / run.norm[0])}


def sumo_rows(out: Path) -> pd.DataFrame:
    """The laws' runs of a control study's output ``out`` (every experiment, every
    seed): events, checks and the output noise, from each run's ``periods.parquet``."""
    rows = []
    for path in sorted(out.glob("*/runs/controller=*,seed=*/periods.parquet")):
        law, seed = (part.split("=")[1] for part in path.parent.name.split(","))
        if law not in LAWS:
            continue
        p = pd.read_parquet(path, columns=["u_continuous", "triggered"])
        rows.append({"experiment": path.parents[2].name, "law": law, "seed": int(seed),
                     "checks": len(p), "events": int(p["triggered"].sum()),
                     "event_share": float(p["triggered"].mean()),
                     "output_noise_veh_h": output_noise_veh_h(p["u_continuous"].to_numpy())})
    if not rows:
        raise StudyError(f"--sumo {out} holds no runs of {', '.join(LAWS)}; allowed: the "
                         f"--out of arzsumo study control")
    return pd.DataFrame(rows)


def summary(rows: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    """Per group of ``by``: mean and 95 % t half-width of events, event share, output
    noise and (where there) the final norm ratio."""
    out = []
    for key, g in rows.groupby(by, sort=True):
        row = dict(zip(by, key if isinstance(key, tuple) else (key,), strict=True))
        row["n"] = len(g)
        for col in ("events", "event_share", "output_noise_veh_h", "final_norm_ratio"):
            if col in g:
                ci = mean_ci(g[col].to_numpy(dtype=float))
                row[col] = ci.mean
                row[f"{col}_pm"] = ci.mean - ci.low
        out.append(row)
    return pd.DataFrame(out)


#: the summary's columns in the markdown tables: column -> (heading, format)
COLUMNS = {"events": ("events", ".0f"), "event_share": ("share of checks", ".2f"),
           "output_noise_veh_h": ("output noise, veh/h", ".3g"),
           "final_norm_ratio": ("final norm ratio", ".3g")}


def readable(table: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    """``table`` (of :func:`summary`) with "mean +- half-width" cells."""
    out = table[[*by, "n"]].copy()
    for col, (head, fmt) in COLUMNS.items():
        if col in table:
            out[head] = [f"{m:{fmt}} +- {h:{fmt}}" if np.isfinite(h) else f"{m:{fmt}}"
                         for m, h in zip(table[col], table[f"{col}_pm"], strict=True)]
    return out.rename(columns={"noise_pct": "noise sd, %"})


@dataclass(frozen=True)
class EtcNoiseOptions:
    """What the study runs and reads, and where it writes.

    The scenario is loaded on construction (a bad one stops there, before the levels are
    checked), so that the options refuse what the study could not run.

    Parameters
    ----------
    scenario : Path
        The scenario whose twin is run.
    levels : tuple of float
        Relative noise sd of the fields, % (each >= 0).
    sumo : Path, optional
        The ``--out`` of ``arzsumo study control``: SUMO's point (None: the twin only).
    seeds : tuple of int
        Noise seeds.
    out : Path
        The study's directory.
    docs : Path, optional
        Also regenerate the study's block of ``docs/PAGE.md`` (None: no page).
    workers : int, optional
        Local processes (None or 1: in this process).
    """

    scenario: Path = shipped_scenarios_dir() / "default.toml"
    levels: tuple[float, ...] = tuple(number_list(LEVELS_PCT))
    sumo: Path | None = None
    seeds: tuple[int, ...] = tuple(range(1, 11))
    out: Path = RESULTS_DIR / NAME
    docs: Path | None = None
    workers: int | None = None

    def __post_init__(self) -> None:
        _scenario(self.scenario)                          # bad input stops here
        if any(level < 0 for level in self.levels):
            raise StudyError(f"--levels {list(self.levels)} is not allowed: numbers >= 0")
        checks.seeds(self.seeds)
        checks.count(self.workers, "workers", optional=True)


@dataclass(frozen=True)
class EtcNoiseResult:
    """The study's outcome: the twin ``runs`` (one row per law, level and seed), their
    ``twin`` summary per law and level, SUMO's summary per experiment and law (``sumo``;
    None without ``opts.sumo``), the markdown ``text`` and the ``files`` written."""

    runs: pd.DataFrame
    twin: pd.DataFrame
    sumo: pd.DataFrame | None
    text: str
    files: tuple[Path, ...]


def tasks(opts: EtcNoiseOptions) -> list[tuple[Path, str, float, int]]:
    """The twin runs: (scenario, law, noise sd in %, noise seed) per level, law and seed."""
    return [(opts.scenario, law, lv, s) for lv in opts.levels for law in LAWS
            for s in opts.seeds]


def design(opts: EtcNoiseOptions) -> list[str]:
    """The twin runs, one line each."""
    return [f"{law}, noise {lv:g} %, seed {s}" for _, law, lv, s in tasks(opts)]


def run_etc_noise(opts: EtcNoiseOptions, *, progress: bool = True) -> EtcNoiseResult:
    """Every (law, level, seed) twin run, the tables, SUMO's point.

    Parameters
    ----------
    opts : EtcNoiseOptions
        The study's options.
    progress : bool, optional
        Show a progress bar while the twin runs.

    Returns
    -------
    EtcNoiseResult
        The runs, their summaries and the files written (``twin_runs.csv``,
        ``twin.csv``, with ``opts.sumo`` ``sumo_runs.csv`` and ``sumo.csv``, and
        ``etc_noise.md`` in ``opts.out``).
    """
    from arzsumo.sweep.driver import map_runs

    sumo = sumo_rows(opts.sumo) if opts.sumo else None
    rows = pd.DataFrame(map_runs(twin_row, tasks(opts), workers=opts.workers or 1,
                                 in_process=not opts.workers or opts.workers == 1,
                                 progress=NAME if progress else None))
    twin = summary(rows, ["law", "noise_pct"])
    text = (f"The twin of `{opts.scenario.name}`, its laws checked on the state with "
            f"relative white noise, seeds {seed_text(list(opts.seeds))} (`arzsumo study "
            f"{NAME}`); mean +- 95 % t half-width.\n\n"
            + markdown_table(readable(twin, ["law", "noise_pct"])))
    table = None
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        written = [write_csv(rows, out / "twin_runs.csv")]
        files = [(write_csv(twin, out / "twin.csv"), "etc_noise_twin.csv")]
        if sumo is not None:
            written.append(write_csv(sumo, out / "sumo_runs.csv"))
            table = summary(sumo, ["experiment", "law"])
            files.append((write_csv(table, out / "sumo.csv"), "etc_noise_sumo.csv"))
            text += ("\n\nThe same laws in SUMO (`--sumo`), per experiment over seeds "
                     f"{seed_text(sorted(sumo['seed'].unique().tolist()))}:\n\n"
                     + markdown_table(readable(table, ["experiment", "law"])))
        written.append(write_text(text, out / "etc_noise.md"))
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "The ETC's trigger against the noise of its state",
                    text, files)
    return EtcNoiseResult(rows, twin, table, text,
                          (*written[:-1], *(p for p, _ in files), written[-1]))
