"""Plots: functions that take arrays (and model types) and return Figures, and
:func:`save_png`.

Imported only by :mod:`arzsumo.outputs` (the writers); imports nothing above the model:
numpy, pandas, matplotlib, and of arzsumo only ``model``, ``io``, ``units`` (contracts in
``pyproject.toml``). Matplotlib's Agg backend is selected here: arzsumo runs headless.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from arzsumo.io import atomic_file


def save_png(fig: Figure, path: str | Path, dpi: int = 110) -> Path:
    """Save ``fig`` as PNG at ``path`` atomically and close it."""
    with atomic_file(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    plt.close(fig)
    return Path(path)
