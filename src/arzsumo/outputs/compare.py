"""Write ``arzsumo compare``: ``comparison.csv`` and ``comparison.png`` from the table of
:mod:`arzsumo.bridge.compare`, and, for a few SUMO runs on one grid, ``fields_hv.png`` and
``fields_av.png``: each run's measured density and speed fields side by side."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.bridge.compare import (
    as_text,
    bar_title,
    check_comparable,
    differing,
    load_summaries,
    row_of,
    summary_table,
)
from arzsumo.io import atomic_file
from arzsumo.outdir import resumable_dir

#: (column of the table, panel title with its unit): the measures the project judges by,
#: each >= 0 by definition (the section's "delay vs V" is not: TTT - TMT / V_free with the
#: model's free speeds turns negative where SUMO's vehicles drive faster, so it is not drawn)
METRICS = (("whole_tts_veh_h", "whole-demand TTS (veh h)"),
           ("ramp_wait_p95_s", "ramp wait, 95th percentile (s)"),
           ("network_time_loss_veh_h", "network time loss (veh h)"),
           ("TTT_veh_h", "section TTT (veh h)"), ("plan_changes", "meter plan changes (count)"))
#: most runs whose fields are drawn side by side
MAX_FIELD_RUNS = 6
#: the Edie fields of a run's cells.parquet, in the order the field figures take
FIELDS = ("rho_h", "v_h", "rho_a", "v_a")


def micro_fields(run: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(t s, x m, fields (n_t, 4, n_x) SI) of the SUMO cells of a run's ``cells.parquet``
    (None without one)."""
    path = run / "cells.parquet"
    if not path.is_file():
        return None
    cells = pd.read_parquet(path, columns=["source", "t_s", "x_m", *FIELDS])
    cells = cells[cells["source"] == "micro"]
    t, x = np.unique(cells["t_s"].to_numpy()), np.unique(cells["x_m"].to_numpy())
    grid = cells.set_index(["t_s", "x_m"])[list(FIELDS)].reindex(
        pd.MultiIndex.from_product([t, x])).to_numpy(float)
    return t, x, grid.reshape(t.size, x.size, 4).transpose(0, 2, 1)


def field_figures(labels: Sequence[str], runs: Sequence[Path],
                  star: tuple[float, float, float, float], target: Path) -> list[Path]:
    """``fields_hv.png`` and ``fields_av.png`` in ``target`` for runs on one grid (at most
    :data:`MAX_FIELD_RUNS`, each with its cells); none otherwise. ``star``: the equilibrium
    (rho_h, v_h, rho_a, v_a), SI, marked on the colour bars (the first run's, as the
    table's header names it for a mixed comparison)."""
    from arzsumo.outputs.figures import save_png
    from arzsumo.plots.bridge import side_by_side_figure

    found = [micro_fields(r) for r in runs]
    if (len(runs) > MAX_FIELD_RUNS or any(f is None for f in found)
            or len({(f[0].tobytes(), f[1].tobytes()) for f in found}) != 1):
        return []
    t, x = found[0][0], found[0][1]
    names = [f"{k + 1}. {label}" if labels.count(label) > 1 else label
             for k, label in enumerate(labels)]      # two runs never share a panel
    panels = {name: f[2] for name, f in zip(names, found, strict=True)}
    return [save_png(side_by_side_figure(t, x, panels, cls, (star[k], star[k + 1]),
                                         "SUMO's Edie cells over the control window"),
                     target / f"fields_{name}.png", dpi=90)
            for cls, k, name in (("h", 0, "hv"), ("a", 2, "av"))]

def _bars(df: pd.DataFrame, means: bool) -> tuple[list[str], dict]:
    """Bar labels and heights (with sd error bars when ``means``) per metric panel."""
    if means:
        grouped = df.groupby("controller", sort=False)
        return [str(c) for c in grouped.groups], {
            label: (grouped[col].mean().to_numpy(float),
                    grouped[col].std().fillna(0.0).to_numpy(float))
            for col, label in METRICS}
    labels = [f"{r.controller} s{as_text(r.seed)}"
              + "".join(f" {c}={as_text(getattr(r, c))}" for c in differing(df))
              for r in df.itertuples()]
    return labels, {label: (df[col].to_numpy(float), None) for col, label in METRICS}


def compare_runs(runs: list[Path], out: Path,
                 allow_mixed: bool = False) -> tuple[str, Path, Path]:
    """Write ``comparison.csv`` and ``comparison.png`` into ``out``; return the text table.

    Refuses (:class:`~arzsumo.bridge.compare.CompareError`, nothing written) results that
    are not comparable unless ``allow_mixed``. ``out`` is claimed as a comparison
    (:func:`arzsumo.outdir.resumable_dir`): new, empty or an earlier comparison, which is
    rewritten; any other directory (a run's results among them) is refused in one line.
    """
    from arzsumo.outputs.figures import save_png
    from arzsumo.plots.evaluation import comparison_figure

    summaries = load_summaries(runs)
    check_comparable(runs, summaries, allow_mixed)
    df = pd.DataFrame([row_of(s) for s in summaries])
    title, means = bar_title(df)
    labels, bars = _bars(df, means)
    with resumable_dir(out, "compare") as target:
        csv = target / "comparison.csv"
        with atomic_file(csv) as tmp:
            df.to_csv(tmp, index=False)
        png = save_png(comparison_figure(labels, bars, title), target / "comparison.png",
                       dpi=100)
        for stale in target.glob("fields_*.png"):     # of an earlier comparison here
            stale.unlink()
        eq = summaries[0].get("equilibrium") or {}
        if not means and all(k in eq for k in FIELDS):
            field_figures(labels, runs, tuple(float(eq[k]) for k in FIELDS), target)
    return summary_table(summaries), csv, png
