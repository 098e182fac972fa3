"""Workflows of the tool that chain runs, fits and reports: the model's identification from
SUMO runs (:mod:`~arzsumo.workflows.identify`, ``arzsumo identify``) and the
reproduction of the paper's section 5 in the twin (:mod:`~arzsumo.workflows.paper`,
``arzsumo reproduce``). They stand on the sweep engine and the output writers.
"""
