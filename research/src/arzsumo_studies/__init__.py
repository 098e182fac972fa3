"""arzsumo_studies: this project's research on arzsumo, apart from the tool.

The studies are experiments built on the twin and SUMO, with their reference values,
record stores and reports: the control study and its ablation, penetration, the premise
gates and their map, the SUMO map (fill, approach, meter dynamics, wave speed, options),
estimation layouts and noise, the share models. :mod:`~arzsumo_studies.cli.catalog` lists
the studies of ``arzsumo study NAME`` (also ``arzsumo-study NAME``).

May import every room of :mod:`arzsumo`; :mod:`arzsumo` never imports this package (an
import contract). Batches run through the sweep engine
(:func:`arzsumo.sweep.driver.map_runs`, or a design of :mod:`arzsumo_studies.design`);
evaluations through :func:`arzsumo.sweep.evaluate.run_evaluation`; files are written
through :mod:`arzsumo.outputs` and :mod:`arzsumo_studies.outputs`.
"""
