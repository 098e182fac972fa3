"""One SUMO run as identification data: :func:`replay_data_of`.

A :class:`~arzsumo.bridge.result.CoSimResult` becomes an :class:`arzsumo.identify.ReplayData`
holding what the bridge's *replay* twin was given (from :mod:`~arzsumo.bridge.boundary_data`,
as the twins) and what it was compared with; under :func:`replay_options_of` the
identification's replay reproduces the bridge's replay field (``tests/bridge/
test_replay_data.py``). docs/identify.md, 'What it does'.
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
    """The run ``res`` as :class:`~arzsumo.identify.ReplayData` (module docstring), SI.

    ``res`` must hold ``start``, the state at control start (a result of
    :func:`~arzsumo.bridge.cosim.run_cosimulation`). ``params``: the model whose Ve fills
    empty cells of the initial and inlet states (default the run's, as its twins did);
    ``name``: the run's label in reports (default ``seed N``). Periods of
    ``res.sumo.control_period`` s, smoothing time constant ``res.settings.smoothing`` s.
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
