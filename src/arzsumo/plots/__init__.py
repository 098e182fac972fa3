"""Plots: functions that take arrays and return Figures, and writers that save them.

Matplotlib's Agg backend is selected here: arzsumo runs headless.
"""

import matplotlib

matplotlib.use("Agg")
