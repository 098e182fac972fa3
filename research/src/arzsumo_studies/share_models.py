"""Per AV share, the stream's own model and design (``arzsumo study share-models``).

A penetration study that keeps one model, one design and one demand for every AV share
confounds the share with an operating point the model does not describe and a demand
the section cannot hold (above 30 % AVs the default no longer inserted its demand).
This study makes, for each share, the scenario the laws are then judged on:

1. **the demand mapped to the share's discharge**: the premise map's two discharge runs
   on a seed no gate reads (:func:`arzsumo_studies.premise.map_study.map_demands`), with the
   mainline demand split by the share; hold 1.01 q(L), fill 1.14 q(L), the fill raised
   by what the queue's tail lacked (research/premise.md);
2. **the model identified there** in two stages (``arzsumo identify --diagram``): the
   diagram from the stationary states with SUMO's wave speed, then the relaxation
   times by the replay, validated on held-out seeds
   (:func:`arzsumo.workflows.identify.study.run_identification`);
3. **the ETC designed for it** (``design-check --auto``:
   :func:`arzsumo.control.design.design_for` on the identified equilibrium), keeping
   the base's dead band settings.

Each share's scenario is written to ``OUT/<point>.toml`` (``av10.toml`` ...), its
identification report to ``OUT/<point>/identify/``, and one row per share to
``share_models.csv`` and ``share_models.md``. The SUMO runs are kept (the discharge
runs in ``OUT/runs``, the identification's in the identification run cache), so a
second call redoes only the fits.
"""

from __future__ import annotations

import json
import math
import re
import shlex
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.errors import require
from arzsumo.io import dump_toml
from arzsumo.outdir import resumable_dir
from arzsumo.units import VEH_H_PER_VEH_S, kmh_to_ms, ms_to_kmh
from arzsumo_studies import checks
from arzsumo_studies.common import RESULTS_DIR, StudyError, scenario_data, shipped_scenario
from arzsumo_studies.outputs.pages import markdown_table, publish, write_csv, write_text
from arzsumo_studies.premise.map_points import MapPoint, demand, mapped_points
from arzsumo_studies.premise.map_study import map_demands

NAME = "share-models"
#: the results page (``research/results/PAGE.md``) this study keeps a block of
PAGE = "share_models"
#: the scenario the study maps by default: the judged configuration of the laws
BASE = "control_newell.toml"
#: the [sumo] keys the mapping sets at every share (:func:`~arzsumo_studies.premise.
#: map_points.demand`): not to be set by hand
MAPPED_KEYS = tuple(demand(0.5))


@dataclass(frozen=True)
class ShareOptions(checks.Shared):
    """What ``arzsumo study share-models`` does.

    ``scenario``: the base scenario (None: :data:`BASE`); ``shares``: AV shares of the
    mainline demand, each in (0, 1); ``train_seeds``, ``validate_seeds``: the
    identification's seeds (disjoint); ``diagram``: stage 1's family; ``kernel_cells``:
    the design's kernel grid; ``out``: the study's directory (resumable); ``workers``,
    ``scheduler``, ``progress``: how the SUMO runs are run; ``docs``: the results page
    to regenerate (None: none).
    """

    scenario: Path | None = None
    shares: tuple[float, ...] = (0.10, 0.18, 0.30, 0.50)
    train_seeds: tuple[int, ...] = (1, 2, 3)
    validate_seeds: tuple[int, ...] = (4, 5, 6)
    diagram: str = "newell"
    jam_floor: str = "cells"
    wave_weight: float = 1.0
    kernel_cells: int = 100
    sumo_keys: tuple[tuple[str, Any], ...] = ()
    out: Path = RESULTS_DIR / NAME
    progress: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        require(bool(self.shares) and all(0.0 < s < 1.0 for s in self.shares)
                and len(set(self.shares)) == len(self.shares), "shares", self.shares,
                "distinct AV shares in (0, 1)", StudyError)
        require(bool(self.train_seeds) and bool(self.validate_seeds)
                and not set(self.train_seeds) & set(self.validate_seeds), "validate_seeds",
                self.validate_seeds, "seeds disjoint from the training seeds", StudyError)
        from arzsumo.workflows.identify.study import JAM_FLOORS

        require(self.jam_floor in JAM_FLOORS, "jam_floor", self.jam_floor,
                f"one of {', '.join(JAM_FLOORS)}", StudyError)
        require(self.wave_weight >= 0.0, "wave_weight", self.wave_weight,
                "a weight >= 0", StudyError)
        if isinstance(self.sumo_keys, Mapping):     # given as a mapping: kept as pairs
            object.__setattr__(self, "sumo_keys", tuple(self.sumo_keys.items()))
        keys = [k for k, _ in self.sumo_keys]
        require(all(re.fullmatch(r"sumo\.[A-Za-z0-9_]+", k) for k in keys)
                and len(set(keys)) == len(keys), "sumo_keys", dict(self.sumo_keys),
                "distinct keys of the [sumo] table (sumo.KEY)", StudyError)
        mapped = [k for k in keys if k.removeprefix("sumo.") in MAPPED_KEYS]
        require(not mapped, "sumo_keys", dict(self.sumo_keys),
                f"keys other than {', '.join(mapped)}: the mapping sets each share's "
                "demand itself", StudyError)
        require(self.kernel_cells >= 10, "kernel_cells", self.kernel_cells,
                "at least 10 cells", StudyError)


@dataclass(frozen=True)
class ShareModel:
    """One share's outcome: its ``point`` name, ``share``, the mapped ``discharge``
    (veh/s), the ``scenario`` file written and its ``row`` of the table."""

    point: str
    share: float
    discharge: float
    scenario: Path
    row: Mapping[str, Any]


@dataclass(frozen=True)
class ShareResult:
    """The study's outcome: per share a :class:`ShareModel`, the ``table`` (one row per
    share) and the mapping's lines."""

    models: tuple[ShareModel, ...]
    table: pd.DataFrame
    mapping: str


def share_points(shares: Sequence[float],
                 keys: Mapping[str, Any] | None = None) -> list[MapPoint]:
    """One mapped point per share, named ``av<percent>``: the base scenario with ``keys``
    (dotted ``sumo.KEY`` values) set."""
    return [MapPoint(f"av{round(100 * s)}", "av_share", dict(keys or {}), mapped=True,
                     av_share=s) for s in shares]


def with_keys(data: Mapping[str, Any], keys: Mapping[str, Any]) -> dict[str, Any]:
    """``data`` (a scenario as written) with dotted ``table.key`` values set."""
    out = {k: dict(v) if isinstance(v, Mapping) else v for k, v in data.items()}
    for dotted, value in keys.items():
        table, _, key = dotted.partition(".")
        out.setdefault(table, {})[key] = value
    return out


def design(opts: ShareOptions) -> list[str]:
    """What the study runs: per share its discharge runs, then the identification's
    training and held-out seeds (``--list``)."""
    from arzsumo.scenario import load_scenario
    from arzsumo_studies.premise.map_points import discharge_runs

    path = opts.scenario or shipped_scenario(BASE)
    points = share_points(opts.shares, dict(opts.sumo_keys))
    lines = [r.run_id for r in discharge_runs(path, points, load_scenario(path).run.warmup)]
    seeds = ",".join(map(str, (*opts.train_seeds, *opts.validate_seeds)))
    return lines + [f"point={p.name},identify seeds={seeds}" for p in points]


def run_share_models(opts: ShareOptions) -> ShareResult:
    """Map, identify and design every share (module docstring); write the scenarios and
    the table."""
    from arzsumo.scenario import load_scenario

    path = opts.scenario or shipped_scenario(BASE)
    base, points = scenario_data(path), share_points(opts.shares, dict(opts.sumo_keys))
    with resumable_dir(opts.out, f"study-{NAME}") as out:
        discharges, shortfalls, text = map_demands(
            path, points, load_scenario(path).run.warmup, out, workers=opts.workers,
            scheduler=opts.scheduler, progress=opts.progress, label=NAME)
        lost = [p.name for p in points if p.name not in discharges]
        if lost:
            raise StudyError(f"shares {', '.join(lost)} gridlocked at the merge in their "
                             "discharge run: no operating point to identify a model at")
        models = [_share_model(opts, base, p, discharges[p.name], out)
                  for p in mapped_points(points, discharges, shortfalls)]
        table = pd.DataFrame([m.row for m in models])
        csv = write_csv(table, out / "share_models.csv")
        body = (f"Per AV share, the demand mapped to its discharge, the model identified "
                f"there and the ETC designed for it (`{command(opts, path)}`; "
                f"[share_models.csv]({PAGE}/share_models.csv), each share's scenario "
                f"beside it: `arzsumo study penetration --share-models "
                f"{opts.docs or 'DOCS'}/{PAGE}` runs the ETC on them).\n\n"
                f"{markdown_table(table)}\n\nThe mapping's discharge runs:\n\n{text}")
        write_text(body, out / "share_models.md")
        if opts.docs is not None:
            publish(opts.docs, PAGE, NAME, "The model and design per AV share", body,
                    [(csv, csv.name), *((m.scenario, m.scenario.name) for m in models)])
    return ShareResult(tuple(models), table, text)


def command(opts: ShareOptions, path: Path) -> str:
    """The command line that makes this study's scenarios."""
    parts = [f"arzsumo study {NAME} --scenario {path}",
             f"--shares {','.join(f'{x:g}' for x in opts.shares)}",
             f"--train-seeds {','.join(map(str, opts.train_seeds))}",
             f"--validate-seeds {','.join(map(str, opts.validate_seeds))}",
             f"--diagram {opts.diagram} --jam-floor {opts.jam_floor}",
             f"--wave-weight {opts.wave_weight:g} --cells {opts.kernel_cells}",
             *(f"--set {shlex.quote(f'{k}={_toml_value(v)}')}" for k, v in opts.sumo_keys)]
    return " ".join(parts)


def _toml_value(value: Any) -> str:
    """``value`` as a TOML value (a JSON string or array of numbers and strings is one)."""
    return str(value).lower() if isinstance(value, bool) else json.dumps(value)


def _share_model(opts: ShareOptions, base: Mapping[str, Any], point: MapPoint,
                 discharge: float, out: Path) -> ShareModel:
    """One share: identify the model on its mapped scenario, design the ETC, write both."""
    from arzsumo.identify import FitSettings
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.workflows.identify.report import identified_toml, write_study
    from arzsumo.workflows.identify.study import make_setup, run_identification

    data = with_keys(base, point.set)
    data["name"] = f"{base.get('name', 'scenario')}_{point.name}"
    mapped = scenario_from_dict(data, str(out / f"{point.name}-mapped.toml"))
    setup = make_setup(mapped, opts.train_seeds, opts.validate_seeds,
                       diagram=opts.diagram, fit=FitSettings(), workers=opts.workers,
                       jam_floor=opts.jam_floor, wave_weight=opts.wave_weight)
    study = run_identification(setup)
    write_study(out / point.name / "identify", study, overwrite=True)
    identified = tomllib.loads(identified_toml(study))
    design, cannot = _design(identified, base, opts.kernel_cells)
    identified["design"] = design
    identified["name"] = data["name"]
    target = out / f"{point.name}.toml"
    write_text(_header(point, discharge, cannot) + dump_toml(identified), target)
    row = _row(point, discharge, study, cannot)
    return ShareModel(point.name, point.av_share, discharge, target, row)


def _design(identified: Mapping[str, Any], base: Mapping[str, Any], cells: int
            ) -> tuple[dict[str, Any], tuple[str, ...]]:
    """The ``[design]`` table that ``design-check --auto`` chooses for the identified
    scenario (the base's dead band settings kept), and the conditions that cannot hold."""
    from arzsumo.control.design import design_for
    from arzsumo.kernel_cache import cached_kernels
    from arzsumo.model.characteristic import linearize
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.scenario.model import design_toml

    sc = scenario_from_dict(dict(identified), "identified.toml")
    lin = linearize(sc.equilibrium)
    choice = design_for(lin.system, cached_kernels(lin.system, cells), base=sc.design)
    table = tomllib.loads(design_toml(choice.design))["design"]
    for key in ("noise_from_estimate", "noise_k"):
        if key in base.get("design", {}):
            table[key] = base["design"][key]
    return table, tuple(choice.cannot_hold)


def _header(point: MapPoint, discharge: float, cannot: Sequence[str]) -> str:
    q = discharge * VEH_H_PER_VEH_S
    held = "all hold" if not cannot else f"cannot hold: {', '.join(cannot)}"
    return (f"# Written by `arzsumo study {NAME}`: AV share {point.av_share:g}, the demand "
            f"mapped to its discharge\n# ({q:.0f} veh/h, seed 100), the model identified "
            f"there in two stages, [design] by\n# design-check --auto (the theorem's "
            f"conditions: {held}).\n")


def _row(point: MapPoint, discharge: float, study: Any,
         cannot: Sequence[str]) -> dict[str, Any]:
    """The table's row of one share (file units)."""
    from arzsumo.model.characteristic import linearize

    lam4 = (ms_to_kmh(linearize(study.equilibrium).eigenvalues[3])
            if study.equilibrium is not None else math.nan)
    gaps = (study.stage_one.wave_gaps("validation", float(kmh_to_ms(lam4)))
            if study.stage_one is not None and math.isfinite(lam4) else {})
    blocks = {v: [r.rmse[v]["blocks_relative"] for r in study.validation.runs]
              for v in ("rho_h", "rho_a")}
    return {"point": point.name, "av_share": point.av_share,
            "discharge_veh_h": discharge * VEH_H_PER_VEH_S,
            **{f"{k}": v for k, v in point.set.items() if "demand" in k},
            "lambda_4_kmh": lam4, "wave_gap_h": gaps.get("h", math.nan),
            "wave_gap_a": gaps.get("a", math.nan),
            "replay_rmse_h_max": max(blocks["rho_h"]),
            "replay_rmse_a_max": max(blocks["rho_a"]),
            "design_cannot_hold": "; ".join(cannot) or "-"}
