"""Write the report of ``arzsumo evaluate``: ``evaluation.csv``, ``evaluation.md`` and
``paired_differences.png``, each atomically, from the table of per-seed results
(statistics in :mod:`arzsumo.evaluation.report`, figure in :mod:`arzsumo.plots.evaluation`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from arzsumo.evaluation.report import MEASURES, Measure, markdown, paired_differences
from arzsumo.io import atomic_file
from arzsumo.outputs.figures import remove_stale_figures

CSV, MARKDOWN, FIGURE = "evaluation.csv", "evaluation.md", "paired_differences.png"


def write_evaluation(out: Path, long: pd.DataFrame, runs: pd.DataFrame,
                     controllers: Sequence[str], header: str, baseline: str = "open",
                     measures: Sequence[Measure] = MEASURES,
                     plots: bool = True) -> list[Path]:
    """Write the long table ``long`` (CSV, Markdown under ``header``) and the figure of the
    per-seed differences of ``runs`` into ``out``; return the paths written. Without the
    figure (``plots`` False, or the open loop alone), one of an earlier call is removed."""
    out = Path(out)
    with atomic_file(out / CSV) as tmp:
        long.to_csv(tmp, index=False)
    with atomic_file(out / MARKDOWN) as tmp:
        tmp.write_text(f"{header}\n\n{markdown(long, baseline)}\n", encoding="utf-8")
    written = [out / CSV, out / MARKDOWN]
    if plots and len(controllers) > 1:
        written.append(paired_figure(out / FIGURE, long, runs, controllers, baseline,
                                     measures))
    else:
        remove_stale_figures(out / FIGURE)
    return written


def paired_figure(path: Path, long: pd.DataFrame, runs: pd.DataFrame,
                  controllers: Sequence[str], baseline: str,
                  measures: Sequence[Measure]) -> Path:
    """The per-seed differences of ``runs`` against ``baseline``, one panel per measure,
    with the mean and 95 % t interval of ``long`` (:func:`~arzsumo.evaluation.report.
    evaluate`), as a PNG at ``path``; return it."""
    from arzsumo.outputs.figures import save_png
    from arzsumo.plots.evaluation import DiffPanel, paired_differences_figure

    panels = []
    for m in measures:
        rows = long[(long["measure"] == m.key) & (long["controller"] != baseline)]
        ci = {r.controller: (r.diff_mean, r.diff_ci_low, r.diff_ci_high)
              for r in rows.itertuples(index=False)}
        better = "lower" if m.lower_is_better else "higher"
        panels.append(DiffPanel(f"{m.label} ({m.unit}; {better} is better)",
                                paired_differences(runs, m, controllers, baseline), ci))
    return save_png(paired_differences_figure(panels, paired_title(runs, controllers,
                                                                   baseline)),
                    path, dpi=100)


def paired_title(runs: pd.DataFrame, controllers: Sequence[str], baseline: str) -> str:
    """The paired figure's title, naming the range of seed counts of the controllers
    other than ``baseline`` (a study's controllers may stand at different counts)."""
    counts = sorted({int(runs.loc[runs["controller"] == c, "seed"].nunique())
                     for c in controllers if c != baseline})
    seeds = "-".join(str(n) for n in dict.fromkeys((counts[0], counts[-1])))
    return (f"minus {baseline}, same seed: dots one seed each ({seeds} seeds), squares "
            "mean with 95 % CI (t)")
