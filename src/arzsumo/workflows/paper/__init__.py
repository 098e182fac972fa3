"""Reproduction of the paper's section 5 on the twin: ``values`` (the paper's numbers),
``reproduce`` (run the scenario files of ``scenarios/paper``), ``compare`` (tables and
verdicts), ``report`` (report text and figure data, written by
:mod:`arzsumo.outputs.reproduce`)."""
