"""Studies: experiments built on the twin and SUMO, with their reference values and
reports. ``paper`` reproduces section 5 of the paper (``arzsumo reproduce``).

May import every room below it (sweep, outputs, bridge, twin, scenarios, sumo, control,
model, io, ...); only the CLI imports studies. Batches run through the sweep engine
(:func:`arzsumo.sweep.driver.map_runs`); files are written through :mod:`arzsumo.outputs`.
"""
