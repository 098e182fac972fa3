"""``arzsumo evaluate``: every controller on the same seeds in SUMO, compared with the open
loop seed by seed.

The runs are a sweep built in code (:func:`evaluation_spec`: the scenario as base, engine
``sumo``, an axis ``controller`` over ``[run] controller``, the seeds last), executed by
:func:`~arzsumo.sweep.driver.run_sweep`: in parallel on local processes or on Dask, and
resumable (a second call with the same output directory runs only what is missing). The
directory is an ``evaluation`` result (its own marker kind, so a sweep directory is not
mistaken for it) laid out like a sweep, plus the report of
:func:`arzsumo.outputs.evaluation.write_evaluation`::

    OUT/  runs/<controller=...,seed=...>/   summary.json, periods.parquet (each run)
          summaries.parquet, sweep.json, sweep.toml, executions.jsonl   (the sweep's)
          evaluation.csv, evaluation.md, paired_differences.png        (the report)
"""

from __future__ import annotations

import re
import shutil
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from arzsumo.evaluation.report import evaluate
from arzsumo.outdir import judge, where
from arzsumo.outputs.evaluation import write_evaluation
from arzsumo.sweep.driver import SweepReport, run_sweep
from arzsumo.sweep.spec import SweepError, SweepSpec, sweep_from_dict
from arzsumo.sweep.worker import FINISHED

#: marker kind of an evaluation directory
KIND = "evaluation"
#: the controller every other one is compared with
BASELINE = "open"
#: what --overwrite removes from a previous evaluation directory (ours: it has our marker)
PREVIOUS = ("runs", "executions.jsonl", "summaries.parquet", "sweep.json", "sweep.toml",
            "evaluation.csv", "evaluation.md", "paired_differences.png")


@dataclass
class EvaluationResult:
    """What :func:`run_evaluation` did: the sweep's report, the finished runs (one row
    each, SI), the long table of the report (human units) and the files written."""

    sweep: SweepReport
    runs: pd.DataFrame
    table: pd.DataFrame
    files: list[Path] = field(default_factory=list)


def check_controllers(controllers: Sequence[str]) -> list[str]:
    """The controllers in order, baseline first (added when missing); unknown or repeated
    names refused."""
    from arzsumo.control.registry import controller_names

    allowed = controller_names("sumo")
    bad = [c for c in controllers if c not in allowed]
    if bad or not controllers:
        raise SweepError(f"--controllers = {','.join(controllers)!r} is not allowed: a "
                         f"comma-separated list of {', '.join(allowed)}")
    repeated = sorted({c for c in controllers if list(controllers).count(c) > 1})
    if repeated:
        raise SweepError(f"--controllers = {','.join(controllers)!r} is not allowed: "
                         f"{', '.join(repeated)} repeated")
    return [BASELINE, *(c for c in controllers if c != BASELINE)]


def evaluation_spec(scenario: Path, controllers: Sequence[str], seeds: Sequence[int],
                    horizon: float | None = None) -> SweepSpec:
    """The sweep of an evaluation: ``scenario`` x controllers x seeds (``horizon``: the
    control horizon, s, instead of ``[sumo] horizon_s``)."""
    scenario = Path(scenario).resolve()
    name = re.sub(r"[^A-Za-z0-9._-]", "_", f"evaluate-{scenario.stem}")
    data: dict = {"name": name, "base": str(scenario), "engine": "sumo",
                  "seeds": list(seeds),
                  "axis": [{"field": "run.controller", "name": "controller",
                            "values": list(controllers)}]}
    if horizon is not None:
        data["set"] = {"sumo": {"horizon_s": float(horizon)}}
    spec = sweep_from_dict(data, f"arzsumo evaluate {scenario}", root=scenario.parent)
    return replace(spec, text=f"# arzsumo evaluate (built in code)\n# base = {scenario}\n"
                              f"# controllers = {list(controllers)}\n# seeds = {list(seeds)}"
                              f"\n# horizon_s = {horizon}\n")


def check_runs(scenario: Path, controllers: Sequence[str], horizon: float | None) -> str:
    """What ``arzsumo run`` checks, for every controller, before any SUMO run starts;
    returns the scenario's name."""
    from arzsumo.bridge.session import prepare_run
    from arzsumo.scenario import load_scenario

    sc = load_scenario(scenario)
    for c in controllers:
        prepare_run(sc, controller=c, horizon=horizon)
    return sc.name


def _forget_previous(out: Path, user: str) -> None:
    """--overwrite: remove the runs and report of a previous evaluation in ``out``."""
    target = out.expanduser().resolve()
    if judge(target, KIND, where(user, target), resumable=True) != "ours":
        return
    for name in PREVIOUS:
        path = target / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists():
            path.unlink()


def run_evaluation(scenario: Path, controllers: Sequence[str], seeds: Sequence[int], *,
                   out: Path, horizon: float | None = None, workers: int | None = None,
                   scheduler: str | None = None, overwrite: bool = False,
                   progress: bool = True, plots: bool = True,
                   command: str = "") -> EvaluationResult:
    """Run ``controllers`` (the open loop added first when missing) on ``seeds`` and write
    the report into ``out`` (module docstring).

    ``out`` may be new, empty, or a previous evaluation: continued (runs already finished
    with the same resolved scenario are not run again), or started afresh with
    ``overwrite``. ``command`` is printed at the top of ``evaluation.md``.
    """
    controllers = check_controllers(controllers)
    name = check_runs(scenario, controllers, horizon)
    spec = evaluation_spec(scenario, controllers, seeds, horizon)
    if overwrite:
        _forget_previous(Path(out), str(out))
    rep = run_sweep(spec, out, workers=workers, scheduler=scheduler, progress=progress,
                    plots=False, kind=KIND)
    df = rep.table if rep.table is not None else pd.DataFrame()
    ok = df[df["status"].isin(FINISHED)]
    table = evaluate(ok, controllers, BASELINE)
    files = write_evaluation(rep.out, table, ok, controllers,
                             _header(name, scenario, controllers, seeds, ok, len(df), command),
                             BASELINE, plots=plots)
    return EvaluationResult(rep, ok, table, files)


def _header(name: str, scenario: Path, controllers: Sequence[str], seeds: Sequence[int],
            ok: pd.DataFrame, total: int, command: str) -> str:
    def one(col: str) -> str:
        vals = sorted({f"{v:g}" for v in ok[col].dropna()}) if col in ok else []
        return ", ".join(vals) or "n/a"

    lines = [f"# Evaluation of scenario {name} ({scenario})", "",
             f"Controllers {', '.join(controllers)} on seeds {', '.join(map(str, seeds))}; "
             f"{len(ok)} of {total} runs finished. Control window: {one('horizon')} s after "
             f"a warm-up of {one('warmup.duration_s')} s. Differences: controller minus "
             f"{BASELINE} on the same seed; 95 % intervals (Student t; the CSV adds the "
             "bootstrap). Network measures cover the control window and every vehicle "
             "loaded (docs/outputs.md)."]
    if command:
        lines += ["", f"Command: `{command}`"]
    return "\n".join(lines)
