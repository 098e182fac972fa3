"""The premise's readings pooled over seeds: the actuator's staircase and the pulse's
mean response, on the seeds that held their demand.

A seed whose mainline demand was mostly not inserted (a merge deadlock, a jammed
approach: under :data:`HELD_INSERTED` of it) shows neither the meter's effect nor the
pulse's: it would only dilute the pooled readings, and paired with a seed for the pulse's
floor it would inflate that floor. So the floors pair the held seeds among themselves,
the pooled readings leave the others out, and both say which seeds they used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from arzsumo_studies.gates import (
    GateResult,
    PremiseError,
    PremiseThresholds,
    mean_response_gate,
)

#: the share of its mainline demand a seed must have inserted to count as held; looser
#: than the ``inserted`` gate's (0.98): it tells a deadlocked seed (0.6) from a seed that
#: held its demand a little short of the gate
HELD_INSERTED = 0.9


def held_seeds(rows: Mapping[int, Mapping[str, Mapping[str, Any]]]) -> tuple[int, ...]:
    """The seeds whose baseline inserted at least :data:`HELD_INSERTED` of its mainline
    demand (a row without the counts counts as held)."""
    out = []
    for s in sorted(rows):
        base = rows[s]["baseline"]
        asked = max(float(base.get("requested_main", 0) or 0), 1.0)
        done = float(base.get("inserted_main", asked))
        if done / asked >= HELD_INSERTED:
            out.append(s)
    return tuple(out)


def _same_grid(rows: Sequence[tuple[Mapping[str, Any], Mapping[str, Any]]]) -> int:
    """The periods every row shares; refuses rows whose t0 or cells differ."""
    first = rows[0][0]
    for b, p in rows:
        for r in (b, p):
            if (float(r["t0_s"]) != float(first["t0_s"])
                    or float(r["dx_m"]) != float(first["dx_m"])
                    or len(r["x_m"]) != len(first["x_m"])):
                raise PremiseError(f"seed {r.get('seed')}: its grid (t0 {r['t0_s']} s, "
                                   f"dx {r['dx_m']} m) is not the first seed's")
    return min(min(len(b["t_s"]), len(p["t_s"])) for b, p in rows)


def pooled_pulse(by_seed: Mapping[int, Mapping[str, Mapping[str, Any]]],
                 seeds: Sequence[int], floors: Mapping[int, Mapping[str, float]],
                 round_trip: float, smooth: float, th: PremiseThresholds) -> GateResult:
    """The pulse's mean response over ``seeds`` (:func:`mean_response_gate`), on the
    periods every seed recorded; unmeasured (NaN, failed, the reason in its detail) with
    fewer than two seeds or fields that do not share one grid."""
    window = th.pulse_round_trips * round_trip
    try:
        rows = [(by_seed[s]["baseline"], by_seed[s]["pulse"]) for s in seeds]
        if len(rows) < 2:
            raise PremiseError(f"{len(rows)} seed(s) held their demand; the mean response "
                               "needs two or more")
        k = _same_grid(rows)
        classes = [c for c in ("hv", "av") if f"v_{c}" in rows[0][0]]
        base = [{c: np.asarray(b[f"v_{c}"], float)[:k] for c in classes} for b, _ in rows]
        puls = [{c: np.asarray(p[f"v_{c}"], float)[:k] for c in classes} for _, p in rows]
        first = rows[0][0]
        gate = mean_response_gate(np.asarray(first["t_s"], float)[:k], base, puls,
                                  float(first["dx_m"]), float(first["t0_s"]), round_trip,
                                  [floors[s] for s in seeds], th, smooth)
        return GateResult(gate.name, gate.value, gate.threshold, gate.passed,
                          {**gate.detail, "seed_list": list(seeds)})
    except PremiseError as exc:
        return GateResult("pulse_mean", math.nan, window, False,
                          {"round_trip_s": round_trip, "seeds": len(seeds),
                           "seed_list": list(seeds), "reason": str(exc)})
