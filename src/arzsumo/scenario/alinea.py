"""The ``[alinea]`` section: ALINEA and PI-ALINEA as practitioners run them.

Occupancy is written in % and held as a fraction inside; gains per % of occupancy in veh/h
are 100/3600 veh/s per unit occupancy (:data:`GAIN_FACTOR`). The loop is read in every run
(open loop too): it is the ``occupancy_out`` column of every periods table. Keys:
docs/scenarios.md; the controllers: docs/sumo.md, "Baselines a practitioner would field".
"""

from __future__ import annotations

from typing import Any

from arzsumo.control.alinea import AlineaSettings
from arzsumo.tables import Key, not_allowed
from arzsumo.units import VEH_H_PER_VEH_S

#: veh/h per % of occupancy per (veh/s per unit occupancy): 3600 / 100 = 36
GAIN_FACTOR = VEH_H_PER_VEH_S / 100.0
#: % per unit occupancy
PCT = 100.0

_GAIN = "a gain > 0 veh/h per % of occupancy"
#: [alinea] key -> AlineaSettings field (SI)
ALINEA_KEYS: dict[str, Key] = {
    "period_s": Key("period", unit="s", allowed="a period in [20, 60] s",
                    doc="the controller's own control period (it holds its command "
                        "between updates)"),
    "loop_distance_m": Key("loop_distance", unit="m",
                           allowed="a distance in [40, 300] m downstream of the merge nose",
                           doc="its E1 loop on `down`, this far downstream of the merge "
                               "nose (the end of `merge`)"),
    "target_pct": Key("target", factor=PCT, unit="%", allowed="an occupancy > 0 %",
                      doc="occupancy target, just below the loop's critical occupancy "
                          "(`arzsumo alinea-target`)"),
    "gain_veh_h_per_pct": Key("gain", factor=GAIN_FACTOR, unit="veh/h per %", allowed=_GAIN,
                              doc="ALINEA's K_R at gain_period_s (scaled to period_s: "
                                  "K_R period_s / gain_period_s)"),
    "gain_period_s": Key("gain_period", unit="s", allowed="a period > 0 s",
                         doc="reference period of gain_veh_h_per_pct and ki_veh_h_per_pct"),
    "kp_veh_h_per_pct": Key("kp", factor=GAIN_FACTOR, unit="veh/h per %",
                            allowed="a gain >= 0 veh/h per % of occupancy",
                            doc="PI-ALINEA's K_P on the change of occupancy (not scaled)"),
    "ki_veh_h_per_pct": Key("ki", factor=GAIN_FACTOR, unit="veh/h per %",
                            allowed="a gain >= 0 veh/h per % of occupancy",
                            doc="PI-ALINEA's K_I at gain_period_s (scaled as K_R)"),
}


def check_alinea_period(settings: AlineaSettings, control_period: float, at: str,
                        written_value: Any = None) -> None:
    """Refuse an ALINEA period that is not a whole number of the closed loop's control
    periods (``[sumo] control_period_s``, s)."""
    n = round(settings.period / control_period)
    if n < 1 or abs(n * control_period - settings.period) > 1e-6:
        value = settings.period if written_value is None else written_value
        raise not_allowed(at, "period_s", value,
                          f"a period in [20, 60] s, a whole multiple of [sumo] "
                          f"control_period_s = {control_period:g} s")
