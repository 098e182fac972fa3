"""Write a twin run to a directory atomically: Parquet fields, control history, summary
(:meth:`arzsumo.engines.twin.TwinRun.summary`), plots. Every file, column (units in the
Parquet field metadata, from :mod:`arzsumo.schema`) and summary key: docs/outputs.md,
"``arzsumo twin``".
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from arzsumo.engines.twin import TwinRun
from arzsumo.io import json_safe
from arzsumo.model.params import VARIABLES
from arzsumo.outdir import OutputDir, atomic_dir, target_of
from arzsumo.schema import TWIN_CONTROL, TWIN_FIELDS, with_units


def fields_table(run: TwinRun) -> pa.Table:
    """The stored fields as a long Arrow table (one row per output time and cell)."""
    r = run.result
    n_t, _, n_x = r.fields.shape
    cols: dict[str, Any] = {"t_s": np.repeat(r.t, n_x), "x_m": np.tile(r.x, n_t)}
    cols.update({name: r.fields[:, k, :].ravel() for k, name in enumerate(VARIABLES)})
    return with_units(pa.table(cols), TWIN_FIELDS, "fields")


def control_table(run: TwinRun) -> pa.Table:
    """Control checks: applied and requested U, the continuous law, events."""
    r = run.result
    log = r.controller.log
    n = r.control_t.size
    cont = np.asarray(log.u_continuous, float) if len(log.u_continuous) == n else \
        np.full(n, np.nan)
    table = pa.table({"t_s": r.control_t, "u_applied": r.control_u,
                      "u_requested": r.control_u_requested, "u_continuous": cont,
                      "triggered": run.events.astype(bool)})
    return with_units(table, TWIN_CONTROL, "control")


def write_run(run: TwinRun, out: str | Path | OutputDir, plots: bool = True,
              overwrite: bool = False) -> Path:
    """Write ``run`` into the directory ``out`` atomically (a previous ``twin`` result is
    replaced only with ``overwrite``, see :mod:`arzsumo.outdir`); return its path."""
    from arzsumo.outputs.figures import save_figures
    from arzsumo.plots.twin import twin_figures

    with atomic_dir(out, "twin", overwrite=overwrite) as tmp:
        pq.write_table(fields_table(run), tmp / "fields.parquet")
        pq.write_table(control_table(run), tmp / "control.parquet")
        (tmp / "summary.json").write_text(json.dumps(json_safe(run.summary()), indent=2)
                                          + "\n", encoding="utf-8")
        if plots:
            save_figures(twin_figures(run), tmp, dpi=110)
    return target_of(out)
