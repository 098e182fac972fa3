"""Figure files: every PNG of arzsumo is saved here, atomically, and its figure closed.

:mod:`arzsumo.plots` draws the figures; here are also the CLI's single-figure writers (the
regime map of ``arzsumo model --regime-map``, the kernels of ``arzsumo kernels --plot``).
Importing this module selects matplotlib's Agg backend: nothing is ever displayed.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from matplotlib.figure import Figure

from arzsumo.io import atomic_file
from arzsumo.plots import plt

if TYPE_CHECKING:                  # annotations only: saving a figure needs neither
    from arzsumo.control.kernels import Kernels
    from arzsumo.model.regime import RegimeMap


def save_png(fig: Figure, path: str | Path, dpi: int = 110) -> Path:
    """Save ``fig`` as PNG at ``path`` (parents made) atomically and close it, also when
    saving fails; return ``path``."""
    try:
        with atomic_file(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png")
    finally:
        plt.close(fig)
    return Path(path)


def save_figures(figs: Mapping[str, Figure], directory: str | Path,
                 dpi: int = 110) -> list[Path]:
    """Save each figure of ``figs`` as ``<name>.png`` in ``directory`` (made if missing),
    in order, and close them all, those not yet saved too if one fails; return the files."""
    directory = Path(directory)
    pending = list(figs.items())
    written = []
    try:
        while pending:
            name, fig = pending.pop(0)
            written.append(save_png(fig, directory / f"{name}.png", dpi=dpi))
    finally:
        for _, fig in pending:
            plt.close(fig)
    return written


def write_regime_map(path: str | Path, rmap: RegimeMap,
                     point: tuple[float, float] | None = None, title: str = "") -> Path:
    """Draw :func:`arzsumo.plots.model.regime_figure` into ``path``; ``point`` is
    (rho_h, rho_a) in veh/m."""
    from arzsumo.plots.model import regime_figure

    return save_png(regime_figure(rmap, point, title), path, dpi=120)


def write_kernels_plot(path: str | Path, kernels: Kernels, title: str = "") -> Path:
    """Draw :func:`arzsumo.plots.model.kernels_figure` of ``kernels`` into ``path``."""
    from arzsumo.plots.model import kernels_figure

    fig = kernels_figure(kernels.x, kernels.K, kernels.M, kernels.L, kernels.N, title)
    return save_png(fig, path, dpi=110)


def remove_stale_figures(*paths: Path) -> list[Path]:
    """Remove the figures ``paths`` that this call did not redraw (``--no-plots``, or
    nothing to draw), so that none of an earlier call is left beside tables it no longer
    matches; return those removed. A directory or symbolic link of that name is left."""
    removed = []
    for path in map(Path, paths):
        if path.is_file() and not path.is_symlink():
            path.unlink()
            removed.append(path)
    return removed
