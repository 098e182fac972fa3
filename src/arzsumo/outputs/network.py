"""The figure of a run's section and its detectors (``arzsumo network --figure``), drawn
from a :class:`~arzsumo.sumo.geometry.RoadGeometry` by :mod:`arzsumo.plots.network`."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from arzsumo.outputs.figures import save_png
from arzsumo.plots import network as plot
from arzsumo.sumo.geometry import RoadGeometry


def network_figure(road: RoadGeometry, title: str = "") -> Figure:
    """The plan and the along-x view of ``road`` (nothing written)."""
    return plot.network_figure(road, title)


def write_network_figure(road: RoadGeometry, path: str | Path, title: str = "") -> Path:
    """Draw ``road`` and save it as PNG at ``path`` (parents made); returns ``path``."""
    return save_png(network_figure(road, title), path, dpi=120)
