"""Outputs: the writers of results (twin runs, co-simulation runs, calibration, ``compare``,
sweep figures, the paper reproduction report, single figures of the CLI).

The only room that imports :mod:`arzsumo.plots`. May import the rooms below it (bridge,
twin, scenarios, sumo, kernel_cache, control, model, plots, io, units, errors); imported
by sweep, studies and the CLI. Every directory or file is written atomically
(:mod:`arzsumo.io`).
"""
