"""One SUMO run as identification data: :func:`replay_data_of`.

A :class:`~arzsumo.bridge.result.CoSimResult` becomes an
:class:`arzsumo.identify.ReplayData` holding what the bridge's *replay* twin was given and
what it was compared with:

* ``fields``: SUMO's Edie cells at the end of every control period (``res.micro``; NaN
  speeds where a class left a cell empty: unobserved);
* ``initial``: the measured state at the start of control (``res.start``), complete:
  empty cells at the equilibrium speed of their densities, densities floored
  (:func:`~arzsumo.bridge.boundary_data.measured_state`);
* ``inlet``: SUMO's first cell, smoothed, period by period
  (:func:`~arzsumo.bridge.boundary_data.inlet_series`, the function the twins use);
* ``outflow``: the total outflow at x = L, smoothed the same way from the nominal
  meter's outflow (:func:`~arzsumo.bridge.boundary_data.outflow_series`);
* ``scale``: the run's equilibrium (rho_h*, v_h*, rho_a*, v_a*), for relative errors.

With :func:`replay_options_of` (the run's twin grid, scheme and AO limit, and the bridge's
``ghost`` inlet), :func:`arzsumo.identify.replay` of this data under the run's parameters
reproduces the bridge's replay field of a run without re-synchronisations (``tests/bridge/
test_replay_data.py`` states the tolerance).
"""

from __future__ import annotations

import numpy as np

from arzsumo.bridge.boundary_data import inlet_series, measured_state, outflow_series
from arzsumo.bridge.result import CoSimResult
from arzsumo.bridge.twins import TWIN_AO_LIMIT
from arzsumo.errors import ArzsumoError
from arzsumo.identify import ReplayData, ReplayOptions
from arzsumo.model.params import ModelParameters
from arzsumo.scenario.run import RunSettings


def replay_options_of(settings: RunSettings, inlet: str = "ghost") -> ReplayOptions:
    """The numerics of the bridge's twins as :class:`~arzsumo.identify.ReplayOptions`:
    ``[run] twin_cells`` and ``twin_scheme``, the bridge's AO limit (flux, limiter and CFL
    are the twin's defaults in both) and, unless ``inlet`` says otherwise, the bridge's
    inlet: the ghost cell's flux as it is (``ghost``; ``ctm`` and ``supply`` bound it by
    the first cell's receiving capacity, :mod:`arzsumo.identify.replay`)."""
    return ReplayOptions(cells=settings.twin_cells, scheme=settings.twin_scheme,
                         ao_limit=TWIN_AO_LIMIT, inlet=inlet)


def replay_data_of(res: CoSimResult, *, params: ModelParameters | None = None,
                   name: str | None = None) -> ReplayData:
    """The run ``res`` as :class:`~arzsumo.identify.ReplayData` (module docstring).

    Parameters
    ----------
    res : CoSimResult
        A finished co-simulation (it must hold ``start``, the state at control start).
    params : ModelParameters, optional
        The model whose equilibrium speed fills empty cells of the initial and inlet
        states; default the run's (``res.equilibrium.params``, as its twins did).
    name : str, optional
        Label of the run in reports; default ``seed N``.

    Returns
    -------
    ReplayData
        SI units; periods of ``res.sumo.control_period`` s, smoothing time constant
        ``res.settings.smoothing`` s.
    """
    if res.start is None:
        raise ArzsumoError("the run holds no state at the start of control; "
                           "allowed: a CoSimResult of run_cosimulation")
    p = params if params is not None else res.equilibrium.params
    dt, tau = res.sumo.control_period, res.settings.smoothing
    initial = measured_state(p, *res.start)
    inlet = inlet_series(p, res.start[:, 0], res.micro[:, :, 0], dt, tau)
    out = res.periods["outflow_h"] + res.periods["outflow_a"]
    outflow = outflow_series(res.q_nominal, out, dt, tau)
    eq = res.equilibrium
    return ReplayData.from_arrays(res.t, res.x, res.micro, initial, inlet, outflow,
                                  scale=np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a]),
                                  name=name or f"seed {res.sumo.seed}")
