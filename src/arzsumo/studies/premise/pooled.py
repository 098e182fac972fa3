"""The premise's readings pooled over seeds: the actuator's staircase and the pulse's
mean response, on the seeds that held the operating point.

A seed whose mainline demand was not inserted (its ``inserted`` gate fails: a merge
deadlock, a jammed approach) shows neither the meter's effect nor the pulse's: it would
only dilute the pooled readings, so they leave it out and report which seeds they used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from arzsumo.evaluation.premise import (
    GateResult,
    PremiseError,
    PremiseThresholds,
    mean_response_gate,
)


def held_seeds(gates: Mapping[int, Sequence[GateResult]]) -> tuple[int, ...]:
    """The seeds whose ``inserted`` gate passed (all seeds of a report without one)."""
    return tuple(s for s, gs in gates.items()
                 if all(g.passed for g in gs if g.name == "inserted"))


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
            raise PremiseError(f"{len(rows)} seed(s) held the operating point; the mean "
                               "response needs two or more")
        classes = [c for c in ("hv", "av") if f"v_{c}" in rows[0][0]]
        k = min(len(b["t_s"]) for b, _ in rows)
        base = [{c: np.asarray(b[f"v_{c}"], float)[:k] for c in classes} for b, _ in rows]
        puls = [{c: np.asarray(p[f"v_{c}"], float)[:k] for c in classes} for _, p in rows]
        first = rows[0][0]
        return mean_response_gate(np.asarray(first["t_s"], float)[:k], base, puls,
                                  float(first["dx_m"]), float(first["t0_s"]), round_trip,
                                  [floors[s] for s in seeds], th, smooth)
    except (PremiseError, ValueError) as exc:
        return GateResult("pulse_mean", math.nan, window, False,
                          {"round_trip_s": round_trip, "seeds": len(seeds),
                           "reason": str(exc)})
