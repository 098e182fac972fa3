"""``arzsumo evaluate``: every controller on the same seeds in SUMO, compared with the open
loop seed by seed: a sweep built in code (:func:`evaluation_spec`) in a directory of its
own marker kind (:data:`KIND`; docs/outputs.md). Runs taken from earlier evaluations
(``--baseline-from``, ``--runs-from``) and when that is allowed: docs/whole_demand.md.
"""

from __future__ import annotations

import copy
import logging
import re
import shutil
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from arzsumo.errors import ArzsumoError
from arzsumo.evaluation.report import evaluate
from arzsumo.io import dump_toml
from arzsumo.outdir import judge, resumable_dir, where
from arzsumo.outputs.evaluation import write_evaluation
from arzsumo.sweep.driver import SweepReport, run_sweep
from arzsumo.sweep.spec import (
    CONTROLLER_ONLY,
    RunSpec,
    SweepError,
    SweepSpec,
    drop_fields,
    sweep_from_dict,
)
from arzsumo.sweep.table import run_dir, sweep_table
from arzsumo.sweep.worker import FINISHED

log = logging.getLogger(__name__)

#: marker kind of an evaluation directory
KIND = "evaluation"
#: the headline measure's column in the sweep table
WHOLE_DEMAND_KEY = "network_whole_demand.time_spent_s.total"
#: the controller every other one is compared with
BASELINE = "open"
#: what --overwrite removes from a previous evaluation directory (ours: it has our marker)
PREVIOUS = ("runs", "executions.jsonl", "summaries.parquet", "sweep.json", "sweep.toml",
            "evaluation.csv", "evaluation.md", "paired_differences.png")


@dataclass
class EvaluationResult:
    """What :func:`run_evaluation` did: the sweep's report, the finished runs (one row
    each, SI), the long table of the report (human units) and the files written."""

    sweep: SweepReport | None      # None: every run was taken from elsewhere
    runs: pd.DataFrame
    table: pd.DataFrame
    files: list[Path] = field(default_factory=list)


#: scenario tables and keys that do not act on an open-loop SUMO run (the open loop holds
#: the nominal plan; sensors and estimators only read; no controller is built): two open
#: runs whose resolved scenarios differ only here are the same SUMO run
OPEN_LOOP_INERT = ("name", "description", "estimation", "sensing", "actuation", "design",
                   "run.controller")


def inert_for(controller: str) -> tuple[str, ...]:
    """Scenario tables and keys that do not act on a SUMO run of ``controller``."""
    own = tuple(k for k, users in CONTROLLER_ONLY.items() if controller not in users)
    base = OPEN_LOOP_INERT if controller == BASELINE else ("name", "description")
    return base + own


#: tables that reach an open-loop SUMO run only through the vehicles placed at t = 0 and
#: the route file (:func:`_sumo_input`); with neither, they drive only the twins
PLACEMENT_ONLY = ("model", "equilibrium", "initial")
#: evaluation measures computed with the model's parameters (section delay: TTT - TMT /
#: v_free): a baseline borrowed under another [model] has them blanked (NaN)
MODEL_DEPENDENT = ("section.total_delay.",)


def check_controllers(controllers: Sequence[str]) -> list[str]:
    """The controllers, baseline first (added when missing); unknown or repeated refused."""
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
                    horizon: float | None = None, warmup: float | None = None) -> SweepSpec:
    """The sweep of an evaluation: ``scenario`` x controllers x seeds; ``horizon`` and
    ``warmup`` (s) replace ``[sumo] horizon_s`` and ``[run] warmup_s``."""
    scenario = Path(scenario).resolve()
    name = re.sub(r"[^A-Za-z0-9._-]", "_", f"evaluate-{scenario.stem}")
    data: dict = {"name": name, "base": str(scenario), "engine": "sumo",
                  "seeds": list(seeds),
                  "axis": [{"field": "run.controller", "name": "controller",
                            "values": list(controllers)}]}
    changes: dict = {}
    if horizon is not None:
        changes["sumo"] = {"horizon_s": float(horizon)}
    if warmup is not None:
        changes["run"] = {"warmup_s": float(warmup)}
    if changes:
        data["set"] = changes
    spec = sweep_from_dict(data, f"arzsumo evaluate {scenario}", root=scenario.parent)
    warm = "" if warmup is None else f"# warmup_s = {warmup}\n"
    return replace(spec, text=f"# arzsumo evaluate (built in code)\n# base = {scenario}\n"
                              f"# controllers = {list(controllers)}\n# seeds = {list(seeds)}"
                              f"\n# horizon_s = {horizon}\n{warm}")


def check_runs(scenario: Path, controllers: Sequence[str], horizon: float | None,
               warmup: float | None = None) -> str:
    """What ``arzsumo run`` checks, for every controller, before any SUMO run starts;
    returns the scenario's name."""
    from arzsumo.bridge.session import prepare_run
    from arzsumo.scenario import load_scenario

    sc = load_scenario(scenario)
    for c in controllers:
        prepare_run(sc, controller=c, horizon=horizon, warmup=warmup)
    return sc.name


def _sumo_input(data: dict) -> tuple[str, float] | None:
    """The route file and road length SUMO is given for the scenario ``data`` (without
    placed vehicles); None when it does not load."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.sumo.demand import route_file_text

    try:
        sc = scenario_from_dict(data)
        return route_file_text(sc.params, sc.sumo), sc.params.length
    except ArzsumoError:
        return None


def _model_inert(a: dict, b: dict) -> bool:
    """Whether [model], [equilibrium] and [initial] leave the open loop of ``a`` and ``b``
    alone: SUMO fills the road itself in both and is given the same route file."""
    starts = {d.get("run", {}).get("start", "warmup") for d in (a, b)}
    if starts != {"warmup"}:
        return False
    ours = _sumo_input(a)
    return ours is not None and ours == _sumo_input(b)


def _without_inert(data: dict, model_inert: bool, inert: Sequence[str]) -> dict:
    out = copy.deepcopy(data)
    drop_fields(out, tuple(inert) + (PLACEMENT_ONLY if model_inert else ()))
    return out


def _first_difference(a: dict, b: dict, prefix: str = "") -> str:
    for key in sorted(set(a) | set(b)):
        if a.get(key) != b.get(key):
            if isinstance(a.get(key), dict) and isinstance(b.get(key), dict):
                return _first_difference(a[key], b[key], f"{prefix}{key}.")
            return f"{prefix}{key}"
    return ""


def _their_run(source: Path, mine: RunSpec, user: str) -> RunSpec:
    """The run in ``source`` matching ``mine``, checked to be the same SUMO run."""
    path = run_dir(source, mine) / "scenario.toml"
    if not (path.parent / "summary.json").is_file():
        raise SweepError(f"--baseline-from = {user} is not allowed: it has no finished run "
                         f"{mine.run_id}; allowed: an evaluation of the same seeds and horizon")
    theirs = tomllib.loads(path.read_text(encoding="utf-8"))
    ours = tomllib.loads(dump_toml(dict(mine.scenario)))
    controller = str(mine.columns.get("controller", BASELINE))
    inert = inert_for(controller)
    model = controller == BASELINE and _model_inert(theirs, ours)
    differ = _first_difference(_without_inert(theirs, model, inert),
                               _without_inert(ours, model, inert))
    if differ:
        also = (f" (and in {', '.join(PLACEMENT_ONLY)} when [run] start = 'warmup' and "
                "SUMO's route file is the same)" if controller == BASELINE else "")
        raise SweepError(f"{user} is not allowed: its run {mine.run_id} differs in "
                         f"{differ}; allowed: runs whose scenarios differ only in "
                         f"{', '.join(inert)}{also}")
    return replace(mine, scenario=theirs)


def borrowed_baseline(spec: SweepSpec, source: Path, user: str) -> pd.DataFrame:
    """The sweep-table rows of the open-loop runs of ``spec`` taken from the earlier
    evaluation in ``source`` (``user``: the directory as the user wrote it)."""
    mine = [r for r in spec.runs() if r.columns.get("controller") == BASELINE]
    theirs = [_their_run(source, r, f"--baseline-from = {user}") for r in mine]
    table = sweep_table(theirs, source)
    if not table["status"].isin(FINISHED).all():
        raise SweepError(f"--baseline-from = {user} is not allowed: its open-loop runs "
                         "cannot be read back; allowed: a finished arzsumo evaluation")
    if any(t.scenario.get("model") != tomllib.loads(dump_toml(dict(m.scenario))).get("model")
           for t, m in zip(theirs, mine, strict=True)):
        table[[c for c in table.columns if c.startswith(MODEL_DEPENDENT)]] = float("nan")
    return table


def borrowed_controller(spec: SweepSpec, source: Path) -> pd.DataFrame | None:
    """The sweep-table rows of every run of ``spec`` (one controller, all seeds) taken
    from the earlier evaluation or sweep in ``source`` (``--runs-from``), or None when
    ``source`` lacks one of them or one there is not the same SUMO run (it is run here)."""
    mine = list(spec.runs())
    if not all((run_dir(source, r) / "summary.json").is_file() for r in mine):
        return None
    try:
        theirs = [_their_run(source, r, f"--runs-from = {source}") for r in mine]
    except SweepError as exc:
        log.info("not taken: %s", exc)
        return None
    table = sweep_table(theirs, source)
    return table if table["status"].isin(FINISHED).all() else None


def _borrow(scenario: Path, controllers: Sequence[str], seeds: Sequence[int],
            horizon: float | None, warmup: float | None,
            sources: Sequence[Path]) -> dict[str, pd.DataFrame]:
    """Per controller found complete in one of ``sources``, its borrowed rows."""
    out: dict[str, pd.DataFrame] = {}
    for c in controllers:
        for source in sources:
            table = borrowed_controller(evaluation_spec(scenario, [c], seeds, horizon, warmup),
                                        Path(source))
            if table is not None:
                out[c] = table.assign(borrowed_from=str(source))
                break
    return out


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
                   out: Path, horizon: float | None = None, warmup: float | None = None,
                   workers: int | None = None,
                   scheduler: str | None = None, share_warmup: bool = True,
                   overwrite: bool = False,
                   progress: bool = True, plots: bool = True,
                   command: str = "", baseline_from: Path | None = None,
                   runs_from: Sequence[Path] = ()) -> EvaluationResult:
    """Run ``controllers`` (the open loop added first when missing) on ``seeds`` and write
    the report into ``out``; the options as in :func:`arzsumo.evaluate`."""
    controllers = check_controllers(controllers)
    name = check_runs(scenario, controllers, horizon, warmup)
    borrowed = pd.DataFrame()
    if baseline_from is not None:
        if len(controllers) == 1:
            raise SweepError(f"--controllers = {BASELINE!r} is not allowed with "
                             "--baseline-from: nothing would run; allowed: at least one "
                             "controller besides the open loop")
        borrowed = borrowed_baseline(
            evaluation_spec(scenario, [BASELINE], seeds, horizon, warmup),
            Path(baseline_from), str(baseline_from))
    others = controllers[1:] if baseline_from else controllers
    taken = _borrow(scenario, others, seeds, horizon, warmup, runs_from)
    to_run = [c for c in others if c not in taken]
    if overwrite:
        _forget_previous(Path(out), str(out))
    rep = None
    if to_run:
        rep = run_sweep(evaluation_spec(scenario, to_run, seeds, horizon, warmup), out,
                        workers=workers, scheduler=scheduler, progress=progress,
                        plots=False, kind=KIND, share_warmup=share_warmup)
        target = rep.out
    else:   # every run taken from elsewhere: only the report is written here
        with resumable_dir(out, KIND) as claimed:
            target = claimed
    df = rep.table if rep is not None and rep.table is not None else pd.DataFrame()
    df = pd.concat([borrowed, *taken.values(), df], ignore_index=True)
    ok = df[df["status"].isin(FINISHED)]
    table = evaluate(ok, controllers, BASELINE)
    head = _header(name, scenario, controllers, seeds, ok, len(df), command)
    if baseline_from:
        head += f"\n\nOpen-loop runs taken from the evaluation in `{baseline_from}`."
    for c, rows in taken.items():
        head += f"\n\nRuns of `{c}` taken from `{rows['borrowed_from'].iloc[0]}`."
    files = write_evaluation(target, table, ok, controllers, head, BASELINE, plots=plots)
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
             "bootstrap). The headline is the whole-demand time spent: every loaded "
             "vehicle from its insertion request to its arrival, the drain after the "
             "window included (docs/outputs.md); the window measures follow."]
    if WHOLE_DEMAND_KEY not in ok or ok[WHOLE_DEMAND_KEY].isna().all():
        lines += ["", "**No whole-demand measures**: the scenario has no drain "
                      "(`[sumo] drain_max_s` = 0), so a queue left at the window's end is "
                      "not charged; compare controllers on the window measures with care."]
    complete = ok.get("network_whole_demand.complete", pd.Series(dtype=object))
    incomplete = int((complete.astype(str).str.lower() == "false").sum())
    if incomplete:
        lines += ["", f"**{incomplete} run(s) did not drain** (a gridlock, or `[sumo] "
                      "drain_max_s`): their whole-demand values are left out."]
    if command:
        lines += ["", f"Command: `{command}`"]
    return "\n".join(lines)
