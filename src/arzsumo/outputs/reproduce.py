"""Write a paper reproduction: ``report.md``, CSV tables, ``summaries.json`` and figures,
atomically; :mod:`arzsumo.workflows.paper.report` builds the content.
"""

from __future__ import annotations

import csv
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.io import json_safe
from arzsumo.outdir import OutputDir, atomic_dir, target_of


@dataclass(frozen=True)
class ReproduceFigures:
    """Plain arrays behind the three reproduction figures (times in s, rates in %).

    ``release``: (run names, update times per run, release time per run, horizon, paper
    label per run name) or None; ``penetration``: (AV %, our triggers, our release times,
    paper triggers, paper release times) or None; ``sensitivity``: parameter -> (values,
    release times, Lyapunov times), with ``paper_design`` the paper's value of each.
    """

    release: tuple[list[str], list[np.ndarray], list[float], float, dict[str, str]] | None
    penetration: tuple[list[float], ...] | None
    sensitivity: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = field(
        default_factory=dict)
    paper_design: dict[str, float] = field(default_factory=dict)


def _write_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    if not rows:
        path.write_text("", encoding="utf-8")
        return
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def write_figures(figs: ReproduceFigures, out: str | Path) -> list[Path]:
    """Write release_instants.png, penetration.png and sensitivity.png (those with data)."""
    from arzsumo.outputs.figures import save_png
    from arzsumo.plots.reproduce import (
        penetration_figure,
        release_instants_figure,
        sensitivity_figure,
    )

    out = Path(out)
    written = []
    if figs.release is not None:
        written.append(save_png(release_instants_figure(*figs.release),
                                out / "release_instants.png", dpi=120))
    if figs.penetration is not None:
        written.append(save_png(penetration_figure(*figs.penetration),
                                out / "penetration.png", dpi=120))
    if figs.sensitivity:
        written.append(save_png(sensitivity_figure(figs.sensitivity, figs.paper_design),
                                out / "sensitivity.png", dpi=120))
    return written


def write_report(out: str | Path | OutputDir, markdown: str,
                 tables: Mapping[str, Sequence[Mapping]], summaries: Mapping[str, Any],
                 figures: ReproduceFigures | None, overwrite: bool = False) -> Path:
    """Write ``report.md``, one ``<name>.csv`` per table, ``summaries.json`` and (unless
    ``figures`` is None) the figures into ``out`` atomically (a previous ``reproduce``
    result is replaced only with ``overwrite``, see :mod:`arzsumo.outdir`); return its path."""
    with atomic_dir(out, "reproduce", overwrite=overwrite) as tmp:
        (tmp / "report.md").write_text(markdown, encoding="utf-8")
        for name, rows in tables.items():
            _write_csv(tmp / f"{name}.csv", rows)
        (tmp / "summaries.json").write_text(
            json.dumps(json_safe(dict(summaries)), indent=1) + "\n", encoding="utf-8")
        if figures is not None:
            write_figures(figures, tmp)
    return target_of(out)
