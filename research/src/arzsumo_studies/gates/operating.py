"""Gate 5, the operating point: is the open loop at the point the model linearises about?

The paper's boundary conditions (section 2) hold the inlet at the equilibrium state and
the outflow at the equilibrium flow plus U; the section sits at one stationary operating
point, and the ramp meter can deliver what the law asks. Four checks per seed:

* :func:`stationarity_gate`: the section's vehicle count has no trend over the window
  (:class:`arzsumo.evaluation.stationarity.CountTrend`; over seeds: on most seeds).
* :func:`inserted_gate`: SUMO inserted at least ``min_inserted`` of the mainline demand
  (vehicles SUMO could not insert wait outside the network: the inlet state is then not
  the demanded one).
* :func:`ramp_demand_gate`: the ramp demand is at most the meter's largest release rate
  (otherwise the ramp queue grows without bound whatever the controller does).
* :func:`ramp_queue_gate`: the open loop's largest ramp queue fits in the ramp's storage
  (otherwise the queue spills back onto the network upstream, outside the model).

Units: veh, veh/s, or whatever the caller uses, the same for both sides of a ratio.
"""

from __future__ import annotations

import math

import numpy as np

from arzsumo.errors import require
from arzsumo.evaluation.stationarity import CountTrend
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds


def stationarity_gate(trend: CountTrend | bool) -> GateResult:
    """The window is stationary (:attr:`CountTrend.stationary`: Kendall's p > 0.05 and
    |drift| < 10 %).

    Parameters
    ----------
    trend : CountTrend or bool
        The seed's count trend, or its ``stationary`` flag.

    Returns
    -------
    GateResult
        Named ``stationary``; ``value`` 1.0 (stationary) or 0.0, threshold 1.0;
        ``detail`` the trend's fields when a CountTrend is given.
    """
    if isinstance(trend, CountTrend):
        flag, detail = trend.stationary, trend.as_dict()
    else:
        require(isinstance(trend, bool | np.bool_), "trend", trend, "a CountTrend or True/False",
                PremiseError)
        flag, detail = bool(trend), {}
    return GateResult("stationary", float(flag), 1.0, bool(flag), detail)


def _ratio(name: str, part: float, whole: float, what: str) -> float:
    require(math.isfinite(part) and part >= 0, name, part, f"a finite {what} >= 0",
            PremiseError)
    require(math.isfinite(whole) and whole > 0, name, whole, f"a finite {what} > 0",
            PremiseError)
    return part / whole


def inserted_gate(inserted: float, demanded: float,
                  thresholds: PremiseThresholds | None = None) -> GateResult:
    """SUMO inserted at least ``min_inserted`` of the mainline demand.

    Parameters
    ----------
    inserted, demanded : float
        Mainline vehicles inserted and demanded over the run (veh, or rates in veh/s).

    Returns
    -------
    GateResult
        Named ``inserted``; ``value`` inserted / demanded (1), passed when >=
        ``min_inserted``.
    """
    th = thresholds or PremiseThresholds()
    share = _ratio("inserted", inserted, demanded, "vehicle count")
    return GateResult("inserted", share, th.min_inserted, bool(share >= th.min_inserted),
                      {"inserted": float(inserted), "demanded": float(demanded)})


def ramp_demand_gate(ramp_demand: float, max_release: float) -> GateResult:
    """The ramp demand is at most the meter's largest release rate.

    Parameters
    ----------
    ramp_demand : float
        Mean ramp demand, veh/s.
    max_release : float
        The meter's largest release rate, veh/s.

    Returns
    -------
    GateResult
        Named ``ramp_demand``; ``value`` demand / largest rate (1), passed when <= 1.
    """
    share = _ratio("ramp_demand", ramp_demand, max_release, "rate, veh/s,")
    return GateResult("ramp_demand", share, 1.0, bool(share <= 1.0),
                      {"ramp_demand_veh_s": float(ramp_demand),
                       "max_release_veh_s": float(max_release)})


def ramp_queue_gate(max_queue: float, storage: float) -> GateResult:
    """The open loop's largest ramp queue fits in the ramp's storage.

    Parameters
    ----------
    max_queue, storage : float
        Largest ramp queue over the run and the ramp's storage, one unit (veh or m).

    Returns
    -------
    GateResult
        Named ``ramp_queue``; ``value`` queue / storage (1), passed when <= 1.
    """
    share = _ratio("ramp_queue", max_queue, storage, "queue")
    return GateResult("ramp_queue", share, 1.0, bool(share <= 1.0),
                      {"max_queue": float(max_queue), "storage": float(storage)})
