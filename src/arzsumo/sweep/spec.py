"""Sweep files: a base scenario, an engine and axes, expanded into runs with stable IDs.

The file's keys, axes (one field or several per value), groups and run IDs:
docs/sweeps.md. The SHA-256 of the resolved scenario tells a finished run from a stale one.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from arzsumo.errors import ScenarioError
from arzsumo.io import read_toml
from arzsumo.scenario import RENAMED, scenario_fields
from arzsumo.scenario.sumo import anchor_meter_curve
from arzsumo.tables import written

ENGINES = ("twin", "sumo")
#: the engine's seed field, set by the ``seeds`` key
SEED_FIELD = {"twin": "twin.seed", "sumo": "sumo.seed"}
#: paper tables that the plots can draw beside a sweep
PAPER_TABLES = ("diffpene", "diffdemands", "sensitivity")
SWEEP_KEYS = {"name", "description", "base", "engine", "seeds", "paper", "baseline", "set",
              "axis"}
AXIS_KEYS = {"field", "name", "values", "set", "group"}
Scalar = bool | int | float | str


class SweepError(ScenarioError):
    """An invalid sweep file, key or value."""


@dataclass(frozen=True)
class Axis:
    """One axis: a column ``name`` and, per value, the fields it sets."""

    name: str
    values: tuple[Scalar, ...]
    sets: tuple[Mapping[str, Any], ...]
    field: str | None = None
    group: str | None = None


#: tables and keys that only some controllers read: for every other controller (the open
#: loop included) they are inert, so two runs that differ only there are the same run
CONTROLLER_ONLY: dict[str, tuple[str, ...]] = {
    "alinea": ("alinea", "pi-alinea"), "run.constant_release_veh_h": ("constant",)}
#: top-level keys that name a scenario and decide no number
LABELS = ("name", "description")


def drop_fields(data: dict[str, Any], names: Iterable[str]) -> None:
    """Remove each table (``sensing``) or key (``run.controller``) of ``names`` from ``data``."""
    for name in names:
        table, _, key = name.partition(".")
        if not key:
            data.pop(table, None)
        elif isinstance(data.get(table), dict):
            data[table].pop(key, None)


def deciding(scenario: Mapping[str, Any], engine: str) -> dict[str, Any]:
    """``scenario`` without what decides none of a run's numbers: its labels and, for a
    SUMO run, the :data:`CONTROLLER_ONLY` tables and keys its controller does not read."""
    data = {k: dict(v) if isinstance(v, Mapping) else v for k, v in scenario.items()
            if k not in LABELS}
    if engine != "sumo":
        return data
    controller = str(data.get("run", {}).get("controller", "open"))
    drop_fields(data, [k for k, users in CONTROLLER_ONLY.items() if controller not in users])
    return data


@dataclass(frozen=True)
class RunSpec:
    """One run of a sweep: its ID, axis values (table columns) and resolved scenario."""

    run_id: str
    index: int
    columns: Mapping[str, Scalar | None]
    overrides: Mapping[str, Any]
    scenario: Mapping[str, Any]
    engine: str
    baseline: bool

    @property
    def sha256(self) -> str:
        """Fingerprint of everything that decides the run's numbers (:func:`deciding`:
        an edit of ALINEA's gains does not make an open loop's result stale)."""
        blob = json.dumps({"engine": self.engine, "baseline": self.baseline,
                           "scenario": deciding(self.scenario, self.engine)},
                          sort_keys=True, default=str)
        return hashlib.sha256(blob.encode()).hexdigest()


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file."""

    name: str
    description: str
    engine: str
    base: Path
    base_data: Mapping[str, Any] = field(repr=False)
    fixed: Mapping[str, Any]
    axes: tuple[Axis, ...]
    paper: str | None = None
    baseline: bool = False
    source: str = "<dict>"
    text: str = field(default="", repr=False)

    @property
    def replicate(self) -> str | None:
        """The column of seeds (error bars in the plots), if the sweep has one."""
        return "seed" if any(a.name == "seed" for a in self.axes) else None

    def runs(self) -> list[RunSpec]:
        """Every run of the sweep, in a stable order (axes in file order, seeds last)."""
        base = _apply(self.base_data, self.fixed)
        factors = [_levels(group, base) for group in _factors(self.axes)]
        runs: list[RunSpec] = []
        for index, combo in enumerate(itertools.product(*factors)):
            columns: dict[str, Scalar | None] = {}
            overrides: dict[str, Any] = {}
            for cols, sets, _ in combo:
                columns.update(cols)
                overrides.update(sets)
            run_id = ",".join(tag for _, _, tag in combo) or "base"
            runs.append(RunSpec(run_id, index, columns, overrides, _apply(base, overrides),
                                self.engine, self.baseline))
        seen: dict[str, int] = {}
        for r in runs:
            if r.run_id in seen:
                raise SweepError(f"{self.source}: runs {seen[r.run_id]} and {r.index} get the "
                                 f"same ID {r.run_id!r}; make the axis values distinct")
            seen[r.run_id] = r.index
        return runs


def _format(value: Scalar) -> str:
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, float) and float(f"{value:g}") == value:
        text = f"{value:g}"
    else:
        text = str(value)
    return re.sub(r"[^A-Za-z0-9._+-]", "_", text)


def _factors(axes: tuple[Axis, ...]) -> list[list[Axis]]:
    """Axes grouped into factors of the product: a group is one factor, at its first axis."""
    factors: list[list[Axis]] = []
    by_group: dict[str, list[Axis]] = {}
    for ax in axes:
        if ax.group is None:
            factors.append([ax])
        elif ax.group in by_group:
            by_group[ax.group].append(ax)
        else:
            by_group[ax.group] = [ax]
            factors.append(by_group[ax.group])
    return factors


def _levels(group: list[Axis], base: Mapping[str, Any]
            ) -> list[tuple[dict[str, Scalar | None], dict[str, Any], str]]:
    """(columns, field overrides, ID part) of each level of one factor."""
    levels = []
    for ax in group:
        for value, sets in zip(ax.values, ax.sets, strict=True):
            cols: dict[str, Scalar | None] = {}
            if ax.group is not None:
                cols[ax.group] = ax.name
                for other in group:
                    if other is not ax:
                        cols[other.name] = _get(base, other.field) if other.field else None
            cols[ax.name] = value
            levels.append((cols, dict(sets), f"{_format(ax.name)}={_format(value)}"))
    return levels


def _get(data: Mapping[str, Any], dotted: str) -> Any:
    table, key = dotted.split(".", 1)
    value = data.get(table, {}).get(key)
    return value if isinstance(value, bool | int | float | str) else None


def _apply(data: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(dict(data))
    for dotted, value in overrides.items():
        table, key = dotted.split(".", 1)
        out.setdefault(table, {})[key] = copy.deepcopy(value)
    return out


def _flat_fields(table: Any, where: str, allowed: Mapping[str, set[str]]) -> dict[str, Any]:
    """``{"table.key": value}`` of a mapping written nested or with dotted keys; checked."""
    if not isinstance(table, Mapping):
        raise SweepError(f"{where} = {written(table)} is not allowed: a table of scenario fields")
    flat: dict[str, Any] = {}

    def walk(prefix: str, body: Mapping[str, Any]) -> None:
        for k, v in body.items():
            name = f"{prefix}.{k}" if prefix else str(k)
            if isinstance(v, Mapping):
                walk(name, v)
            else:
                flat[name] = v

    walk("", table)
    for name in flat:
        _check_field(name, where, allowed)
    return flat


def _check_field(name: str, where: str, allowed: Mapping[str, set[str]]) -> None:
    parts = name.split(".")
    if len(parts) != 2 or parts[0] not in allowed:
        raise SweepError(f"{where}: field {name!r} is not allowed: 'table.key' with table one "
                         f"of {', '.join(sorted(allowed))}")
    new = RENAMED.get(parts[0], {}).get(parts[1])
    if new is not None:
        raise SweepError(f"{where}: field {name!r} was renamed: write "
                         f"'{parts[0]}.{new}' instead")
    if parts[1] not in allowed[parts[0]]:
        raise SweepError(f"{where}: field {name!r} is not allowed: [{parts[0]}] has "
                         f"{', '.join(sorted(allowed[parts[0]]))}")


def _scalar(value: Any, where: str) -> Scalar:
    if isinstance(value, float) and not math.isfinite(value):
        raise SweepError(f"{where}: value {written(value)} is not allowed: a finite number")
    if not isinstance(value, bool | int | float | str):
        raise SweepError(f"{where}: value {written(value)} is not allowed: a number, string or "
                         "boolean (use set = [...] for lists)")
    return value


def _axis(raw: Any, i: int, source: str, allowed: Mapping[str, set[str]]) -> Axis:
    where = f"{source} [[axis]] {i}"
    if not isinstance(raw, Mapping):
        raise SweepError(f"{where} is not allowed: a table")
    for key in raw:
        if key not in AXIS_KEYS:
            raise SweepError(f"{where}: unknown key {key!r}; allowed: "
                             f"{', '.join(sorted(AXIS_KEYS))}")
    values = raw.get("values")
    if not isinstance(values, list) or not values:
        raise SweepError(f"{where}: values = {written(values)} is not allowed: a non-empty list")
    vals = tuple(_scalar(v, where) for v in values)
    repeated = sorted({_format(v) for v in vals if [_format(w) for w in vals].count(
        _format(v)) > 1})
    if repeated:
        raise SweepError(f"{where}: values repeat {', '.join(repeated)}")
    if ("field" in raw) == ("set" in raw):
        raise SweepError(f"{where}: give either field (one field per value) or set (a table "
                         "of fields per value)")
    group = raw.get("group")
    if group is not None and not isinstance(group, str):
        raise SweepError(f"{where}: group = {written(group)} is not allowed: a string")
    if "field" in raw:
        fld = raw["field"]
        if not isinstance(fld, str):
            raise SweepError(f"{where}: field = {written(fld)} is not allowed: 'table.key'")
        _check_field(fld, where, allowed)
        name = str(raw.get("name", fld.split(".", 1)[1]))
        return Axis(name, vals, tuple({fld: v} for v in vals), fld, group)
    sets = raw["set"]
    if not isinstance(sets, list) or len(sets) != len(vals):
        raise SweepError(f"{where}: set must be a list of {len(vals)} tables (one per value), "
                         f"got {written(sets)}")
    if "name" not in raw or not isinstance(raw["name"], str):
        raise SweepError(f"{where}: name (the column of this axis) is missing")
    flat = tuple(_flat_fields(s, f"{where} set", allowed) for s in sets)
    return Axis(raw["name"], vals, flat, None, group)


def sweep_from_dict(data: Mapping[str, Any], source: str = "<dict>",
                    root: Path | None = None) -> SweepSpec:
    """Validate a parsed sweep file; ``base`` is read relative to ``root``."""
    unknown = [k for k in data if k not in SWEEP_KEYS]
    if unknown:
        raise SweepError(f"{source}: unknown key {', '.join(repr(k) for k in unknown)}; "
                         f"allowed: {', '.join(sorted(SWEEP_KEYS))}")
    engine = data.get("engine", "twin")
    if engine not in ENGINES:
        raise SweepError(f"{source}: engine = {written(engine)} is not allowed: one of "
                         f"{', '.join(ENGINES)}")
    if "base" not in data:
        raise SweepError(f"{source}: base (the scenario file the runs start from) is missing")
    if not isinstance(data["base"], str):
        raise SweepError(f"{source}: base = {written(data['base'])} is not allowed: a path "
                         "(a string) relative to the sweep file")
    if "description" in data and not isinstance(data["description"], str):
        raise SweepError(f"{source}: description = {written(data['description'])} is not "
                         "allowed: a string")
    base = (root or Path.cwd()) / data["base"]
    _, base_data = read_toml(base, f"{source}: base", SweepError)
    # file paths inside a scenario are relative to the file that names them
    base_data = anchor_meter_curve(base_data, base.parent)
    allowed = scenario_fields()
    fixed = _anchor(_flat_fields(data.get("set", {}), f"{source} [set]", allowed), root)
    raw_axes = data.get("axis", [])
    if not isinstance(raw_axes, list):
        raise SweepError(f"{source}: axis must be an array of tables ([[axis]])")
    axes = [_axis(a, i + 1, source, allowed) for i, a in enumerate(raw_axes)]
    axes = [replace(a, sets=tuple(_anchor(s, root) for s in a.sets)) for a in axes]
    if "seeds" in data:
        seeds = data["seeds"]
        if isinstance(seeds, int) and not isinstance(seeds, bool) and seeds >= 1:
            seeds = list(range(1, seeds + 1))      # a count, as `arzsumo evaluate --seeds`
        if not isinstance(seeds, list) or not seeds or any(
                isinstance(s, bool) or not isinstance(s, int) or s < 0 for s in seeds):
            raise SweepError(f"{source}: seeds = {written(seeds)} is not allowed: a count N "
                             ">= 1 (seeds 1..N) or a non-empty list of integers >= 0")
        axes.append(_axis({"field": SEED_FIELD[engine], "name": "seed", "values": seeds},
                          len(axes) + 1, source, allowed))
    names = [a.name for a in axes]
    groups = {a.group for a in axes if a.group}
    dup = sorted({n for n in names if names.count(n) > 1} | (groups & set(names)))
    if dup:
        raise SweepError(f"{source}: axis and group names must differ; repeated: "
                         f"{', '.join(dup)}")
    paper = data.get("paper")
    if paper is not None and paper not in PAPER_TABLES:
        raise SweepError(f"{source}: paper = {written(paper)} is not allowed: one of "
                         f"{', '.join(PAPER_TABLES)}")
    baseline = data.get("baseline", False)
    if not isinstance(baseline, bool):
        raise SweepError(f"{source}: baseline = {written(baseline)} is not allowed: true or false")
    name = data.get("name", Path(source).stem)
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9._-]+", name):
        raise SweepError(f"{source}: name = {written(name)} is not allowed: letters, digits, . _ -")
    return SweepSpec(name, str(data.get("description", "")), engine, base, base_data, fixed,
                     tuple(axes), paper, baseline, source)


def _anchor(flat: Mapping[str, Any], root: Path | None) -> dict[str, Any]:
    """Flat fields with a relative ``sumo.meter_curve`` made relative to the sweep file."""
    key = "sumo.meter_curve"
    if key not in flat:
        return dict(flat)
    data = anchor_meter_curve({"sumo": {"meter_curve": flat[key]}}, root or Path.cwd())
    return {**flat, key: data["sumo"]["meter_curve"]}


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and validate a sweep file."""
    path = Path(path)
    text, data = read_toml(path, "sweep", SweepError)
    return replace(sweep_from_dict(data, str(path), root=path.parent), text=text)
