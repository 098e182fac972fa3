"""How the ETC's event trigger meets the noise of the state it sees (``arzsumo study
etc-noise``).

In SUMO the designed ETC of the default may update its U at almost every check, as
continuous backstepping does, where in the noise-free twin it updates at a fraction of
them. This study puts the difference down to a number: the nonlinear twin of the scenario
(its model, its ``[design]``, its ``[twin]`` and ``[initial]`` tables), with the PDE laws
checked on the state through relative white noise of sd ``--levels`` per field, cell and
check (:class:`~arzsumo.control.noise.NoisyState`), on ``--seeds`` noise seeds. Per level
and law it reports the events (updates of the held U), the noise of the law's output (the
sd of its change from one check to the next, veh/h) and the deviation norm's final ratio.

With ``--sumo DIR`` (the output of ``arzsumo study control``) it adds the same two
numbers read off SUMO's runs there (``periods.parquet``: ``u_continuous``, ``triggered``),
so SUMO's point can be read against the twin's curve: which noise level gives SUMO's
output noise, and how many events the trigger fires at that level.
"""

from __future__ import annotations

import argparse
import functools
import logging
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from arzsumo.control.noise import NoisyState
from arzsumo.engines.twin import run_twin, twin_controller
from arzsumo.evaluation.stats import mean_ci
from arzsumo.model.characteristic import linearize
from arzsumo.outdir import resumable_dir
from arzsumo.outputs.studies import markdown_table, publish, write_csv, write_text
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import load_scenario
from arzsumo.studies.common import (
    StudyError,
    add_output,
    add_runs,
    number_list,
    print_list,
    seed_text,
)
from arzsumo.units import veh_s_to_veh_h

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
    checks = len(ctrl.log.t)
    return {"law": law, "noise_pct": level_pct, "seed": seed, "checks": checks,
            "events": run.triggers, "event_share": run.triggers / max(checks, 1),
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


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The study's options."""
    parser.add_argument("--scenario", type=Path,
                        default=shipped_scenarios_dir() / "default.toml", metavar="FILE",
                        help="the scenario whose twin is run (default: the shipped default)")
    parser.add_argument("--levels", type=number_list, default=number_list(LEVELS_PCT),
                        metavar="LIST", help="relative noise sd of the fields, %% "
                                             f"(default: {LEVELS_PCT})")
    parser.add_argument("--sumo", type=Path, metavar="DIR",
                        help="the --out of `arzsumo study control`: SUMO's point")
    add_runs(parser, seeds="1-10")
    add_output(parser, NAME, PAGE, plots=False)


def run(args: argparse.Namespace) -> int:
    """Every (law, level, seed) twin run, the tables, SUMO's point."""
    from arzsumo.sweep.driver import map_runs

    load_scenario(args.scenario)                          # bad input stops here
    if any(level < 0 for level in args.levels):
        raise StudyError(f"--levels {args.levels} is not allowed: numbers >= 0")
    tasks = [(args.scenario, law, lv, s) for lv in args.levels for law in LAWS
             for s in args.seeds]
    if args.list:
        return print_list([f"{law}, noise {lv:g} %, seed {s}" for _, law, lv, s in tasks])
    sumo = sumo_rows(args.sumo) if args.sumo else None
    rows = pd.DataFrame(map_runs(twin_row, tasks, workers=args.workers or 1,
                                 in_process=not args.workers or args.workers == 1,
                                 progress=None if args.quiet else NAME))
    twin = summary(rows, ["law", "noise_pct"])
    text = (f"The twin of `{args.scenario.name}`, its laws checked on the state with "
            f"relative white noise, seeds {seed_text(args.seeds)} (`arzsumo study {NAME}`); "
            "mean +- 95 % t half-width.\n\n"
            + markdown_table(readable(twin, ["law", "noise_pct"])))
    with resumable_dir(args.out, f"study-{NAME}") as out:
        write_csv(rows, out / "twin_runs.csv")
        files = [(write_csv(twin, out / "twin.csv"), "etc_noise_twin.csv")]
        if sumo is not None:
            write_csv(sumo, out / "sumo_runs.csv")
            table = summary(sumo, ["experiment", "law"])
            files.append((write_csv(table, out / "sumo.csv"), "etc_noise_sumo.csv"))
            text += ("\n\nThe same laws in SUMO (`--sumo`), per experiment over seeds "
                     f"{seed_text(sorted(sumo['seed'].unique().tolist()))}:\n\n"
                     + markdown_table(readable(table, ["experiment", "law"])))
        write_text(text, out / "etc_noise.md")
        if args.docs is not None:
            publish(args.docs, PAGE, NAME, "The ETC's trigger against the noise of its state",
                    text, files)
    print(text)
    return 0
