"""The actuation stage of the closed loop: the controller's U to a ramp-meter command.

A PDE controller's U (veh/s) is the deviation of the section's outflow from q* (paper,
section 2): the meter is asked for the mainline outflow ``q_nominal + U``, where
``q_nominal`` is the outflow of the nominal plan on the meter's calibrated curve, so U = 0
is the open loop. The open loop itself never commands the meter: it keeps the nominal
plan, and no plan change is counted.
"""

from __future__ import annotations

from arzsumo.sumo.meter import MeterLight


class MeterActuator:
    """Commands ``meter`` with the outflow ``q_nominal + U``.

    Parameters
    ----------
    meter : MeterLight
        The meter of the open run (fixed cycle: the outflow ``q_nominal + U`` through its
        curve; one per green: the release rate of
        :func:`~arzsumo.sumo.meter_release.release_rate_for`).
    q_nominal : float
        Mainline outflow of the nominal plan, veh/s.
    hold_nominal : bool
        Keep the nominal plan whatever U is (the open loop).
    """

    def __init__(self, meter: MeterLight, q_nominal: float, hold_nominal: bool) -> None:
        self.meter, self.q_nominal, self.hold_nominal = meter, q_nominal, hold_nominal

    def apply(self, u: float) -> float:
        """Command U (veh/s); return the green share commanded (in [0, 1])."""
        if self.hold_nominal:
            return self.meter.green_share
        return self.meter.command(u, self.q_nominal)
