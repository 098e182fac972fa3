"""Studies: experiments built on the twin and SUMO, with their reference values and
reports. ``paper`` reproduces section 5 of the paper (``arzsumo reproduce``),
``identify`` identifies the model (``arzsumo identify``), and :mod:`~arzsumo.studies.
catalog` lists the studies of ``arzsumo study NAME`` (the ablation of the PDE controllers,
the meter's dynamics, the approach map, the estimation layouts, ...).

May import every room below it (sweep, outputs, bridge, twin, scenarios, sumo, control,
model, io, ...); only the CLI imports studies. Batches run through the sweep engine
(:func:`arzsumo.sweep.driver.map_runs`, or a design of :mod:`arzsumo.studies.design`);
evaluations through :func:`arzsumo.sweep.evaluate.run_evaluation`; files are written
through :mod:`arzsumo.outputs`.
"""
