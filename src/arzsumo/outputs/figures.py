"""Single-figure writers of the CLI: the regime map (``arzsumo model --regime-map``) and the
kernels (``arzsumo kernels --plot``), saved as PNG atomically."""

from __future__ import annotations

from pathlib import Path

from arzsumo.control.kernels import Kernels
from arzsumo.model.regime import RegimeMap
from arzsumo.plots import save_png


def write_regime_map(path: str | Path, rmap: RegimeMap,
                     point: tuple[float, float] | None = None, title: str = "") -> Path:
    """Draw :func:`arzsumo.plots.regime.regime_figure` into ``path``; ``point`` is
    (rho_h, rho_a) in veh/m."""
    from arzsumo.plots.regime import regime_figure

    return save_png(regime_figure(rmap, point, title), path, dpi=120)


def write_kernels_plot(path: str | Path, kernels: Kernels, title: str = "") -> Path:
    """Draw :func:`arzsumo.plots.kernels.kernels_figure` of ``kernels`` into ``path``."""
    from arzsumo.plots.kernels import kernels_figure

    fig = kernels_figure(kernels.x, kernels.K, kernels.M, kernels.L, kernels.N, title)
    return save_png(fig, path, dpi=110)
