"""Sweeps: a base scenario, an engine (twin or SUMO) and axes, run on a process pool or
a Dask cluster, resumable and failure-isolated, summarised in one tidy table
(docs/sweeps.md). :func:`~arzsumo.sweep.driver.map_runs` runs any batch on the same
backends.

Never imports studies or the CLI: reference values drawn on its figures come from the
caller (``run_sweep(..., paper=...)``).
"""

from arzsumo.sweep.driver import run_sweep
from arzsumo.sweep.spec import SweepError, SweepSpec, load_sweep, sweep_from_dict
from arzsumo.sweep.table import comparable

__all__ = ["SweepError", "SweepSpec", "comparable", "load_sweep", "run_sweep",
           "sweep_from_dict"]
