"""Figure writers of the studies (:mod:`arzsumo_studies`): each draws one of the
Figures of :mod:`arzsumo.plots` and saves it as PNG atomically."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from arzsumo.outputs.figures import save_png

#: the figures of :func:`write_mechanism_figures`
MECHANISM_FIGURES = ("map.png", "shift.png")

def write_mechanism_figures(runs: pd.DataFrame, pairs: pd.DataFrame,
                            levels: Mapping[float, float], out: Path) -> list[Path]:
    """``map.png`` (outflow against green share, every run of ``runs``) and ``shift.png``
    (the paired spread change against the mean-speed change of ``pairs``) in ``out``."""
    from arzsumo_studies.plots.ablation import mechanism_map_figure, mechanism_shift_figure

    drawn = (mechanism_map_figure(runs, levels), mechanism_shift_figure(pairs))
    return [save_png(fig, Path(out) / name, dpi=120)
            for fig, name in zip(drawn, MECHANISM_FIGURES, strict=True)]


def write_meter_steps_figure(data: Mapping[int, Mapping[str, np.ndarray]],
                             models: Mapping[int, tuple[np.ndarray, np.ndarray]],
                             ensembles: Sequence, path: Path) -> Path:
    """The meter-dynamics figure (:func:`arzsumo_studies.plots.meter_dynamics.steps_figure`)."""
    from arzsumo_studies.plots.meter_dynamics import steps_figure

    return save_png(steps_figure(data, models, ensembles), path, dpi=110)


def write_approach_map(points: pd.DataFrame, runs: pd.DataFrame, tag: str, path: Path,
                       sd_min: float = 10.0, inserted_min: float = 0.98) -> Path:
    """The approach map (:func:`arzsumo_studies.plots.approach.approach_map_figure`)."""
    from arzsumo_studies.plots.approach import approach_map_figure

    return save_png(approach_map_figure(points, runs, tag, sd_min, inserted_min), path,
                    dpi=110)


def write_u_series(series: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str,
                   path: Path) -> Path:
    """U over time per state acted on (:func:`arzsumo_studies.plots.u_estimate.u_series_figure`)."""
    from arzsumo_studies.plots.u_estimate import u_series_figure

    return save_png(u_series_figure(series, title), path, dpi=90)


def write_reach_figure(conditions: Mapping[str, Mapping[str, object]], path: Path) -> Path:
    """The reach figure (:func:`arzsumo_studies.plots.coherence.reach_figure`: condition ->
    boundary -> coherent share) as PNG at ``path``."""
    from arzsumo_studies.plots.coherence import reach_figure

    return save_png(reach_figure(conditions), path, dpi=120)
