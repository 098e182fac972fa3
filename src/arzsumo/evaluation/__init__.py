"""Evaluation: statistics over seeds (:mod:`~arzsumo.evaluation.stats`), the measures and
table of ``arzsumo evaluate`` (:mod:`~arzsumo.evaluation.report`) and the measures of
space-time fields (``fields``, ``waves``, ``travel``, ``decay``); docs/layout.md.

Importing this package imports neither libsumo nor sumolib.
"""

from arzsumo.evaluation.stats import (
    MeanCI,
    PairedComparison,
    StatisticsError,
    bootstrap_mean_ci,
    mean_ci,
    paired_difference,
    wins_losses,
)

__all__ = ["MeanCI", "PairedComparison", "StatisticsError", "bootstrap_mean_ci", "mean_ci",
           "paired_difference", "wins_losses"]
