"""Plots: functions that take arrays (and model types, or a result read by attribute) and
return matplotlib Figures; :mod:`arzsumo.outputs.figures` saves and closes them. Imported
only by :mod:`arzsumo.outputs` (contracts in ``pyproject.toml``). Matplotlib's Agg backend
is selected here: arzsumo runs headless.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

__all__ = ["plt"]
