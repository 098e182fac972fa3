"""Whole-demand accounting: every loaded vehicle, from its insertion request to its arrival.

A ramp meter that holds vehicles back looks free when the measures stop at the end of the
control window, its queue uncharged. With ``[sumo] drain_max_s`` > 0 the run goes on until
every loaded vehicle has left (:mod:`arzsumo.bridge.drain`), and ``network_whole_demand``
holds SUMO's tripinfo measures of every vehicle, the drain, the per-step integral of
vehicles in the system and the ramp waits (docs/outputs.md, "Whole demand").
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

    ``trips``: :func:`~arzsumo.sumo.network_measures.read_trips` rows; ``crossings``: the
    stop line's releases, vehicle id and SUMO steps since t = 0 when its front had left
    ``ramp_up`` (:class:`arzsumo.sumo.stop_line.StopLine`); ``dt``: SUMO step, s;
    ``free_time``: free-flow travel time over ``ramp_up``, s. The wait is the crossing
    time minus the wanted departure minus ``free_time``, at least 0; NaN for a vehicle
    still upstream of the line at the end.
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
    crossed = done.size > 0
    return {"vehicles": int(done.size), "mean": float(done.mean()) if crossed else math.nan,
            "p95": float(np.percentile(done, 95)) if crossed else math.nan,
            "max": float(done.max()) if crossed else math.nan,
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
