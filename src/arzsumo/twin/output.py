"""Write a twin run to a directory: Parquet fields, control history, summary, plots.

Layout of ``DIR`` (written atomically with :func:`arzsumo.io.atomic_dir`)::

    fields.parquet    long table: t_s, x_m, rho_h, v_h, rho_a, v_a (SI: veh/m, m/s)
    control.parquet   t_s, u_applied, u_requested, u_continuous, triggered (veh/s)
    summary.json      :meth:`arzsumo.twin.run.TwinRun.summary`
    fields_h.png, fields_a.png, control.png
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from arzsumo.io import atomic_dir, target_of
from arzsumo.outdir import OutputDir
from arzsumo.twin.run import TwinRun


def fields_table(run: TwinRun) -> pa.Table:
    """The stored fields as a long Arrow table (one row per output time and cell)."""
    r = run.result
    n_t, _, n_x = r.fields.shape
    cols: dict[str, Any] = {"t_s": np.repeat(r.t, n_x), "x_m": np.tile(r.x, n_t)}
    for k, name in enumerate(("rho_h", "v_h", "rho_a", "v_a")):
        cols[name] = r.fields[:, k, :].ravel()
    return pa.table(cols)


def control_table(run: TwinRun) -> pa.Table:
    """Control checks: applied and requested U, the continuous law, events."""
    r = run.result
    log = r.controller.log
    n = r.control_t.size
    cont = np.asarray(log.u_continuous, float) if len(log.u_continuous) == n else \
        np.full(n, np.nan)
    return pa.table({"t_s": r.control_t, "u_applied": r.control_u,
                     "u_requested": r.control_u_requested, "u_continuous": cont,
                     "triggered": run.events.astype(bool)})


def json_safe(obj: Any) -> Any:
    """``obj`` with numpy scalars as Python numbers and non-finite floats as None."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, np.generic):
        return json_safe(obj.item())
    return obj


def write_run(run: TwinRun, out: str | Path | OutputDir, plots: bool = True,
              overwrite: bool = False) -> Path:
    """Write ``run`` into the directory ``out`` atomically (a previous ``twin`` result is
    replaced only with ``overwrite``, see :mod:`arzsumo.outdir`); return its path."""
    from arzsumo.plots.twin import write_twin_plots

    with atomic_dir(out, "twin", overwrite=overwrite) as tmp:
        pq.write_table(fields_table(run), tmp / "fields.parquet")
        pq.write_table(control_table(run), tmp / "control.parquet")
        (tmp / "summary.json").write_text(json.dumps(json_safe(run.summary()), indent=2)
                                          + "\n", encoding="utf-8")
        if plots:
            write_twin_plots(run, tmp)
    return target_of(out)
