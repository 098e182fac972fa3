"""Write the figures of a sweep (``plots/study.png`` or ``plots/sensitivity.png``) from
the table of finished runs and the :class:`SweepLayout` of :mod:`arzsumo.sweep.driver`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from arzsumo.control.etc import PAPER_DESIGN


@dataclass(frozen=True)
class SweepLayout:
    """What the figures need to know of a sweep: its name, engine (``twin`` or ``sumo``),
    replicate column (the seed axis, or None) and axes as (name, one-at-a-time group or
    None), in the sweep file's order."""

    name: str
    engine: str
    replicate: str | None
    axes: Sequence[tuple[str, str | None]]


def write_sweep_plots(ok: pd.DataFrame, layout: SweepLayout, out: str | Path,
                      paper: Mapping[str, Mapping[float, float]] | None = None) -> list[Path]:
    """Write the figures of a sweep from the table ``ok`` of its finished runs into ``out``.

    A one-at-a-time group gives ``sensitivity.png`` (dotted: the paper's design);
    otherwise the first axis that is not the seed is the abscissa of ``study.png``, the
    other axes give one line each, and ``paper`` (metric -> {axis value: value}) is drawn
    beside them.
    """
    from arzsumo.outputs.figures import save_png
    from arzsumo.plots.sweep import sensitivity_figure, study_figure

    out = Path(out)
    metrics = [m for m in ("triggers", "release_time", "plan_changes") if m in ok.columns
               and ok[m].notna().any()]
    if ok.empty or not metrics:
        return []
    engine = "SUMO" if layout.engine == "sumo" else "PDE twin"
    rep = layout.replicate
    seeds = f", mean and sd over {ok[rep].nunique()} seeds" if rep else ""
    groups = [group for _, group in layout.axes if group]
    if groups:
        pars = [name for name, group in layout.axes if group == groups[0]]
        marks = {p: float(getattr(PAPER_DESIGN, p)) for p in pars
                 if isinstance(getattr(PAPER_DESIGN, p, None), int | float)}
        fig = sensitivity_figure(ok, groups[0], pars, metrics, marks,
                                 f"{layout.name}: {engine}{seeds}; dotted: paper's design")
        return [save_png(fig, out / "sensitivity.png", dpi=120)]
    study = [name for name, _ in layout.axes if name != rep]
    if not study:
        return []
    fig = study_figure(ok, study[0], metrics, lines=study[1:], paper=paper,
                       title=f"{layout.name}: {engine}{seeds}", label=engine)
    return [save_png(fig, out / "study.png", dpi=120)]
