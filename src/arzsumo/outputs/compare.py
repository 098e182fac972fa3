"""Write ``arzsumo compare``: ``comparison.csv`` and ``comparison.png`` from the table of
:mod:`arzsumo.bridge.compare`."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from arzsumo.bridge.compare import load_summaries, row_of, summary_table
from arzsumo.io import atomic_file


def compare_runs(runs: list[Path], out: Path) -> tuple[str, Path, Path]:
    """Write ``comparison.csv`` and ``comparison.png`` into ``out``; return the text table."""
    from arzsumo.plots import save_png
    from arzsumo.plots.compare import comparison_figure

    summaries = load_summaries(runs)
    df = pd.DataFrame([row_of(s) for s in summaries])
    out.mkdir(parents=True, exist_ok=True)
    csv = out / "comparison.csv"
    with atomic_file(csv) as tmp:
        df.to_csv(tmp, index=False)
    png = save_png(comparison_figure(df), out / "comparison.png", dpi=100)
    return summary_table(summaries), csv, png
