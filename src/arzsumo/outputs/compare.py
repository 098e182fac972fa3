"""Write ``arzsumo compare``: ``comparison.csv`` and ``comparison.png`` from the table of
:mod:`arzsumo.bridge.compare`."""

from __future__ import annotations

from pathlib import Path

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
    from arzsumo.plots.compare import comparison_figure

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
    return summary_table(summaries), csv, png
