"""The fixed-cycle meter's calibration: mainline outflow against green share, and its plans.

:class:`GreenShareCurve` is the measured mainline outflow at the merge against the
meter's green share (``arzsumo calibrate``), which :class:`arzsumo.sumo.meter.RampMeter`
inverts; :func:`plan_green_steps` makes a green share a timing of whole SUMO steps; the U
range and the ramp's floor of that meter follow from the curve. Pure functions; no SUMO.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import ArzsumoError, require
from arzsumo.sumo.config import SumoConfig


@dataclass(frozen=True)
class GreenShareCurve:
    """Mainline outflow (veh/s) measured at green shares (ascending, in [0, 1]).

    Outflows must not increase with the green share (ramp vehicles take capacity).
    """

    green_share: tuple[float, ...]
    outflow: tuple[float, ...]

    def __post_init__(self) -> None:
        g, q = np.asarray(self.green_share, float), np.asarray(self.outflow, float)
        require(g.size >= 2 and g.size == q.size, "green_share", self.green_share,
                "at least two points, as many as outflow values", ArzsumoError)
        require(bool(np.all(np.diff(g) > 0)) and g[0] >= 0 and g[-1] <= 1, "green_share",
                self.green_share, "strictly increasing values in [0, 1]", ArzsumoError)
        require(bool(np.all(q > 0)), "outflow", self.outflow, "flows greater than 0 veh/s",
                ArzsumoError)

    def monotone(self) -> GreenShareCurve:
        """The curve made non-increasing (running minimum), for a unique inverse."""
        q = np.minimum.accumulate(np.asarray(self.outflow, float))
        return GreenShareCurve(self.green_share, tuple(float(v) for v in q))

    def outflow_at(self, g: float) -> float:
        """Mainline outflow (veh/s) at green share ``g`` (linear interpolation)."""
        return float(np.interp(g, self.green_share, self.outflow))

    def green_share_for(self, q: float) -> float:
        """Green share giving mainline outflow ``q`` (veh/s), saturated at the curve's ends."""
        m = self.monotone()
        g, out = np.asarray(m.green_share), np.asarray(m.outflow)
        return float(np.interp(q, out[::-1], g[::-1]))


#: Mainline outflow against green share on the default network, 6 s cycle, medium demand
#: (4104 HV/h + 1560 AV/h, ramp 1200 veh/h, seed 42, 450 s, mean after 150 s), as written
#: by ``arzsumo calibrate`` to ``meter_curve.toml`` (load others with
#: :func:`arzsumo.sumo.calibration_io.load_green_share_curve`).
DEFAULT_CURVE = GreenShareCurve((0.0, 0.25, 0.5, 0.75, 1.0),
                                (5664 / 3600, 4512 / 3600, 4464 / 3600, 3300 / 3600,
                                 3240 / 3600))


def plan_green_steps(g: float, cycle: int, min_green: int, min_red: int) -> int:
    """Green steps per cycle of ``cycle`` steps for green share ``g`` in [0, 1].

    A green shorter than ``min_green`` steps becomes 0 (all red) or ``min_green``,
    whichever is nearer; a red shorter than ``min_red`` becomes 0 (all green) or
    ``min_red``. So g = 0 is always red and g = 1 always green.
    """
    require(math.isfinite(g) and 0.0 <= g <= 1.0, "green_share", g, "a number in [0, 1]",
            ArzsumoError)
    green = round(g * cycle)
    if 0 < green < min_green:
        green = 0 if green < min_green / 2 else min_green
    if 0 < cycle - green < min_red:
        green = cycle if cycle - green < min_red / 2 else cycle - min_red
    return green


def fixed_cycle_u_range(curve: GreenShareCurve, cfg: SumoConfig,
                        q_nominal: float) -> tuple[float, float]:
    """The U (veh/s) a fixed-cycle meter can command: the monotone curve's outflow between
    ``green_share_max`` (least mainline outflow) and ``green_share_min``, minus q*;
    widened to include 0 (the nominal plan is always allowed)."""
    m = curve.monotone()
    return (min(0.0, m.outflow_at(cfg.green_share_max) - q_nominal),
            max(0.0, m.outflow_at(cfg.green_share_min) - q_nominal))


def fixed_cycle_ramp_floor(curve: GreenShareCurve, cfg: SumoConfig, q_nominal: float,
                           queue: float) -> float:
    """Least U (veh/s) the ramp can deliver with ``queue`` vehicles waiting.

    ``q_open - r - queue / H - q*`` capped at 0, with ``q_open`` the curve's outflow at
    green share 0, ``r`` ``[sumo] ramp_demand`` and ``H = max(meter cycle, control
    period)`` s: the ramp releases at most its arrivals and its queue, each release taking
    one mainline vehicle's place (docs/sumo.md, "Actuation limits").
    """
    q_open = curve.monotone().outflow_at(0.0)
    horizon = max(cfg.meter_cycle, cfg.control_period)
    return min(0.0, q_open - cfg.ramp_demand - queue / horizon - q_nominal)
