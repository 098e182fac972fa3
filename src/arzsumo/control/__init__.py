"""Controllers: backstepping kernels and laws, event-triggered control, observers, baselines.

Pure math: no SUMO, no files, no plotting. May import ``model``, ``units`` and ``errors``
(contracts in ``pyproject.toml``, checked by ``lint-imports``).
"""
