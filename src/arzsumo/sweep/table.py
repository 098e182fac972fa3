"""The tidy table of a sweep: one row per run, axes as columns, then the summary's numbers.

Nested summary entries become dotted columns; lists are left out (they stay in each run's
``summary.json``). SI units, as in the summaries; :func:`arrow_table` stores each column's
unit in the Parquet field metadata (:mod:`arzsumo.schema`; docs/outputs.md).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa

from arzsumo.schema import (
    RUN_SUMMARY,
    SWEEP_FIXED,
    TEXT,
    TWIN_SUMMARY,
    Column,
    scenario_field_unit,
    summary_unit,
    with_units,
)
from arzsumo.sweep.spec import Axis, RunSpec

#: columns that measure the execution, not the traffic: they differ between two
#: executions of the same run and are left out when tables are compared
VOLATILE = ("execution.", "wall_time", "numerics.wall_time_s", "numerics.speed_up",
            "timings.", "controller_time_per_period")
#: the marker kind of one run's directory in a sweep (``runs/<run_id>/``)
RUN_KIND = "sweep-run"
#: summary entries that are not table columns
SKIP = {"sweep", "settings_resolved", "units", "units_by_key"}


def flatten(summary: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Scalar leaves of a nested summary with dotted names; lists left out."""
    out: dict[str, Any] = {}
    for key, value in summary.items():
        if not prefix and key in SKIP:
            continue
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten(value, f"{name}."))
        elif value is None or isinstance(value, bool | int | float | str):
            out[name] = value
    return out


def run_dir(out: Path, run: RunSpec) -> Path:
    """Where a run's outputs live."""
    return out / "runs" / run.run_id


def sweep_record(run: RunSpec, status: str, execution: Mapping[str, Any]) -> dict[str, Any]:
    """The ``sweep`` entry of a run's stored document: identity, fingerprint, outcome."""
    return {"run_id": run.run_id, "index": run.index, "columns": dict(run.columns),
            "overrides": dict(run.overrides), "sha256": run.sha256, "engine": run.engine,
            "status": status, "execution": dict(execution)}


def scenario_text(run: RunSpec, toml: str) -> str:
    """The text of a run's ``scenario.toml``: its resolved scenario ``toml``, headed."""
    return f"# run {run.run_id} of a sweep: the resolved scenario\n{toml}"


def read_record(out: Path, run: RunSpec) -> tuple[str, dict[str, Any]] | None:
    """(status, stored document) of the run's current result, or None: one made from
    another resolved scenario (another SHA-256) is stale."""
    for name in ("summary.json", "error.json"):
        path = run_dir(out, run) / name
        if not path.is_file():
            continue
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError):
            return None
        record = doc.get("sweep", {})
        if record.get("sha256") == run.sha256:
            return str(record.get("status")), doc
        return None
    return None


def uniform_types(col: pd.Series) -> pd.Series:
    """An object column Parquet can store: mixed Python types become strings."""
    if col.dtype != object:
        return col
    kinds = {type(v) for v in col if v is not None and not (isinstance(v, float)
                                                            and math.isnan(v))}
    if len(kinds) <= 1 or kinds <= {int, float}:
        return col
    return col.map(lambda v: v if v is None else str(v))


def table_row(run: RunSpec, found: tuple[str, Mapping[str, Any]] | None) -> dict[str, Any]:
    """The table row of ``run`` from its (status, stored document), or marked missing."""
    row: dict[str, Any] = {"run_id": run.run_id, "index": run.index, **run.columns}
    if found is None:
        row.update(status="missing", error=None)
        return row
    status, doc = found
    row.update(status=status, error=doc.get("error"), warnings=len(doc.get("warnings", [])))
    row.update({f"execution.{k}": v for k, v in doc.get("sweep", {}).get("execution", {}).items()})
    row.update({k: v for k, v in flatten(doc).items() if k not in row})
    return row


def sweep_table(runs: Iterable[RunSpec], out: Path) -> pd.DataFrame:
    """The table of every run of the sweep as stored under ``out`` (missing runs marked)."""
    df = pd.DataFrame([table_row(run, read_record(out, run)) for run in runs])
    return df.apply(uniform_types)


def comparable(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` without the columns that measure the execution (:data:`VOLATILE`)."""
    keep = [c for c in df.columns if not any(c == v or c.startswith(v) for v in VOLATILE)]
    return df[keep].sort_values("index").reset_index(drop=True)


def _axis_columns(axes: Iterable[Axis], df: pd.DataFrame) -> dict[str, Column]:
    """Units of the axis columns: from the scenario field's suffix (``_kmh``: km/h, ...)."""
    out: dict[str, Column] = {}
    for ax in axes:
        if ax.group is not None:
            out[ax.group] = Column(TEXT, f"which axis of group {ax.group} this run varies")
        numeric = ax.name in df and pd.api.types.is_numeric_dtype(df[ax.name].dtype) \
            and not pd.api.types.is_bool_dtype(df[ax.name].dtype)
        unit = (scenario_field_unit(ax.field) if ax.field else None) or \
            ("1" if numeric and ax.name != "seed" else TEXT)
        where = f"scenario field {ax.field}" if ax.field else "values set by the sweep file"
        out[ax.name] = Column(unit, f"sweep axis {ax.name!r}: {where}, in scenario-file units")
    return out


def table_columns(df: pd.DataFrame, axes: Iterable[Axis] = ()) -> dict[str, Column]:
    """Unit and meaning of every column of the sweep table ``df``; a summary key that
    :mod:`arzsumo.schema` does not describe (an old summary's) gets unit ``?``."""
    cols = {**SWEEP_FIXED, **_axis_columns(axes, df)}
    for name in df.columns:
        if name not in cols:
            unit = summary_unit(name, RUN_SUMMARY) or summary_unit(name, TWIN_SUMMARY) or "?"
            cols[name] = Column(unit, f"summary.json entry {name}")
    return cols


def arrow_table(df: pd.DataFrame, axes: Iterable[Axis] = ()) -> pa.Table:
    """The sweep table as Arrow, with per-column units (what ``summaries.parquet`` holds)."""
    table = pa.Table.from_pandas(df, preserve_index=False)
    return with_units(table, table_columns(df, axes), "summaries")
