"""Plots: functions that take arrays (and model types, or a result read by attribute) and
return matplotlib Figures, or a dict of them by name. Nothing here touches the file
system: the figures are saved, and closed, by :mod:`arzsumo.outputs.figures`.

Imported only by :mod:`arzsumo.outputs` (the writers); imports nothing above the model:
numpy, pandas, matplotlib, and of arzsumo only ``model`` and ``units`` (contracts in
``pyproject.toml``). Matplotlib's Agg backend is selected here: arzsumo runs headless.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

__all__ = ["plt"]
