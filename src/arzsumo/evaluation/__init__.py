"""Evaluation: statistics over seeds (and, in :mod:`arzsumo.sumo.network_measures`,
network-wide measures from SUMO's own outputs).

* :mod:`~arzsumo.evaluation.stats`: mean with a 95 % t interval, paired differences
  treatment - baseline with t and bootstrap intervals, wins and losses per seed.
* :mod:`~arzsumo.evaluation.fields` and :mod:`~arzsumo.evaluation.waves`: block means of
  space-time fields, their oscillation, direction of travel, stop-and-go band power and
  growth upstream, and the lateral files of a class.
* :mod:`~arzsumo.evaluation.report`: the measures of ``arzsumo evaluate`` and their table
  (per controller: mean and CI; paired difference against the open loop, wins, losses).
* :mod:`~arzsumo.evaluation.travel`: the speed of travel of a field's fluctuations (the
  lag of the peak cross-correlation between places).

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
