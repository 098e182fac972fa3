"""Evaluation: statistics over seeds (:mod:`~arzsumo.evaluation.stats`), the measures and
table of ``arzsumo evaluate`` (:mod:`~arzsumo.evaluation.report`) and the measures of
space-time fields (``fields``, ``waves``, ``travel``, ``decay``); docs/layout.md.

Importing this package imports neither libsumo nor sumolib.
"""
