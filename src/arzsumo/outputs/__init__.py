"""Outputs: the writers of results (twin runs, co-simulation runs, calibration, ``compare``,
sweep figures, the paper reproduction report, single figures of the CLI), each directory or
file written atomically; the only room that imports :mod:`arzsumo.plots` (docs/layout.md).
"""
