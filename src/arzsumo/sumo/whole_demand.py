"""Whole-demand accounting: every loaded vehicle, from its insertion request to its arrival.

A ramp meter that holds vehicles back looks free when the measures stop at the end of the
control window: its queue is still there, uncharged. The demand here is finite (the fill,
the hold, then nothing: flows end with the control window) and, with ``[sumo] drain_max_s``
> 0, the run goes on after the window until every loaded vehicle has left the network
(:mod:`arzsumo.bridge.drain`). The block ``network_whole_demand`` of ``summary.json``
then holds SUMO's tripinfo measures of every vehicle (the keys of
:func:`~arzsumo.sumo.network_measures.aggregate`), plus:

* ``complete``: whether the drain emptied the network (completed = loaded), and
  ``drain``: its length (s), its limit, whether the run hit it, and whether it ended on a
  gridlock (no arrival for :data:`arzsumo.bridge.drain.STALL_S` with teleports off);
* ``in_system_integral_s``: the per-step integral of the vehicles in the system (on the
  network or waiting to be inserted), counted by libsumo every step: an independent
  check of ``time_spent_s.total`` (equal within a step per vehicle);
* ``ramp_wait_s``: the wait of each ramp vehicle at the meter, from its insertion request
  to its front crossing the stop line, less the free-flow time over ``ramp_up``
  (:func:`ramp_waits`): mean, 95th percentile, maximum, and the count over
  :data:`WAIT_LIMIT_S` (the 4-min cap of Minnesota's practice).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

#: a ramp wait beyond this is counted (s): the cap Minnesota's practice puts on it
WAIT_LIMIT_S = 240.0


def ramp_waits(trips: pd.DataFrame, crossings: Sequence[tuple[str, int]], dt: float,
               free_time: float) -> pd.Series:
    """Wait of each ramp vehicle at the meter, s (index: vehicle id).

    Parameters
    ----------
    trips : DataFrame
        :func:`~arzsumo.sumo.network_measures.read_trips` rows (``depart_s``,
        ``depart_delay_s``, ``origin``).
    crossings : sequence of (str, int)
        The stop line's releases: vehicle id and SUMO steps since t = 0 when its front had
        left ``ramp_up`` (:class:`arzsumo.sumo.meter.StopLine`).
    dt : float
        SUMO step, s.
    free_time : float
        Free-flow travel time over ``ramp_up``, s (its length over its speed limit).

    Returns
    -------
    Series
        Crossing time minus the wanted departure minus ``free_time``, at least 0, s, for
        every ramp vehicle that crossed; NaN for one still upstream of the line at the end.
    """
    ramp = trips[trips["origin"] == "ramp"]
    inserted = np.where(ramp["depart_s"] >= 0, ramp["depart_s"], np.nan)
    due = pd.Series(inserted - ramp["depart_delay_s"].to_numpy(), index=ramp["id"])
    crossed = pd.Series({v: k * dt for v, k in crossings}, dtype=float)
    wait = crossed.reindex(due.index) - due - free_time
    return wait.clip(lower=0.0)


def wait_summary(waits: pd.Series, limit: float = WAIT_LIMIT_S) -> dict[str, Any]:
    """Mean, 95th percentile and maximum of ``waits`` (s; NaN: not crossed), the
    vehicles over ``limit`` (s) and those that never crossed."""
    done = waits.dropna().to_numpy()
    if not done.size:
        return {"vehicles": 0, "mean": math.nan, "p95": math.nan, "max": math.nan,
                "over_limit": 0, "limit_s": limit, "not_crossed": int(waits.isna().sum())}
    return {"vehicles": int(done.size), "mean": float(done.mean()),
            "p95": float(np.percentile(done, 95)), "max": float(done.max()),
            "over_limit": int(np.sum(done > limit)), "limit_s": limit,
            "not_crossed": int(waits.isna().sum())}


def whole_demand_summary(network: dict[str, Any], waits: pd.Series, integral_s: float,
                         drain_s: float, drain_max: float,
                         gridlock: bool = False) -> dict[str, Any]:
    """The ``network_whole_demand`` block (module docstring) from the whole run's
    ``network`` dict (its end after the drain), the ramp ``waits`` (s), the per-step
    integral of vehicles in the system (veh s), the drain's length and limit (s) and
    whether it ended on a gridlock."""
    veh = network["vehicles"]
    complete = veh["completed"]["total"] == veh["loaded"]["total"]
    return {"window": "whole demand: every loaded vehicle from its insertion request to its "
                      "arrival (warm-up, control window and drain)",
            **network, "complete": bool(complete),
            "drain": {"duration_s": drain_s, "max_s": drain_max,
                      "hit_limit": not complete and not gridlock, "gridlock": gridlock},
            "in_system_integral_s": integral_s, "ramp_wait_s": wait_summary(waits)}
