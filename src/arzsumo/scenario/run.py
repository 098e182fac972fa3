"""The ``[run]`` section: what ``arzsumo run`` does around SUMO (keys: docs/scenarios.md).

ALINEA's and PI-ALINEA's parameters are the ``[alinea]`` table; the control horizon, the
control period and the seed are ``[sumo]`` keys.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from arzsumo.control.registry import controller_names
from arzsumo.errors import ScenarioError, require
from arzsumo.tables import Key, not_allowed
from arzsumo.units import VEH_H_PER_VEH_S

#: backstepping kernel grid of both `arzsumo run` and `arzsumo twin` (one default)
KERNEL_CELLS = 100

#: [run] key -> RunSettings field (SI), with its unit factor
RUN_KEYS: dict[str, Key] = {
    "controller": Key("controller", "string", doc="controller on the ramp meter (a name of "
                                                  "the registry that runs in SUMO)"),
    "warmup_s": Key("warmup", unit="s", doc="time under the nominal meter before control"),
    "start": Key("start", "string", choices=("warmup", "placement"),
                 doc="\"placement\": vehicles placed from [initial] at t = 0"),
    "operating_point": Key("equilibrium", "string", choices=("scenario", "measured"),
                           doc="equilibrium the controller is designed at: the scenario's, "
                               "or measured over the last 60 s of the warm-up"),
    "kernel_cells": Key("kernel_cells", "integer", doc="grid of the backstepping kernels"),
    "twin_cells": Key("twin_cells", "integer", doc="grid of the twins alongside SUMO"),
    "twin_scheme": Key("twin_scheme", "string", choices=("first", "muscl"),
                       doc="scheme of the twins alongside SUMO"),
    "smoothing_s": Key("smoothing", unit="s",
                       doc="time constant of the measured boundary data fed to the twins"),
    "constant_release_veh_h": Key("constant_release", factor=VEH_H_PER_VEH_S,
                                  allowed="a rate > 0 veh/h, within [sumo] "
                                          "release_rate_min_veh_h .. release_rate_max_veh_h",
                                  unit="veh/h", doc="release rate of the `constant` "
                                                    "controller in SUMO (sweep it to find "
                                                    "the best constant rate)"),
}
#: keys renamed since earlier versions: old -> new (refused with a one-line hint)
RUN_RENAMED = {"equilibrium": "operating_point",
               "alinea_gain_veh_h_per_pct": "[alinea] gain_veh_h_per_pct"}


#: [run] keys that act only from the start of control: runs differing in them share a
#: warm-up (it holds the nominal plan whatever the controller; arzsumo.bridge.branches)
WINDOW_ONLY_RUN_KEYS = ("controller", "constant_release_veh_h")


@dataclass(frozen=True)
class RunSettings:
    """Settings of one co-simulation (SI; ``constant_release`` in veh/s)."""

    controller: str = "etc"
    warmup: float = 150.0
    start: str = "warmup"
    equilibrium: str = "scenario"
    kernel_cells: int = KERNEL_CELLS
    twin_cells: int = 100
    twin_scheme: str = "muscl"
    smoothing: float = 30.0
    constant_release: float = 600.0 / 3600.0

    def __post_init__(self) -> None:
        def check(ok: bool, name: str, allowed: str) -> None:
            require(ok, name, getattr(self, name), allowed, ScenarioError)

        names = controller_names("sumo")
        check(self.controller in names, "controller", f"one of {', '.join(names)}")
        check(math.isfinite(self.warmup) and self.warmup >= 0, "warmup", "a time >= 0 s")
        check(self.start in ("warmup", "placement"), "start", "'warmup' or 'placement'")
        check(self.equilibrium in ("scenario", "measured"), "equilibrium",
              "'scenario' or 'measured'")
        check(self.equilibrium == "scenario" or self.warmup >= 60, "equilibrium",
              "'measured' needs warmup_s >= 60 (it averages the last 60 s)")
        for name in ("kernel_cells", "twin_cells"):
            check(isinstance(getattr(self, name), int) and getattr(self, name) >= 10, name,
                  "an integer >= 10")
        check(self.twin_scheme in ("first", "muscl"), "twin_scheme", "'first' or 'muscl'")
        check(self.smoothing > 0, "smoothing", "a time > 0 s")
        check(math.isfinite(self.constant_release) and self.constant_release > 0,
              "constant_release", "a rate > 0 veh/s")

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def check_constant_release(settings: RunSettings, low: float, high: float, at: str,
                           written_value: Any = None) -> None:
    """Refuse a ``constant`` controller whose release rate lies outside the meter's
    bounds ``[low, high]`` (veh/s)."""
    r = settings.constant_release
    if settings.controller == "constant" and not low - 1e-12 <= r <= high + 1e-12:
        value = written_value if written_value is not None else r * VEH_H_PER_VEH_S
        raise not_allowed(at, "constant_release_veh_h", value,
                          f"a rate in [{low * VEH_H_PER_VEH_S:g}, "
                          f"{high * VEH_H_PER_VEH_S:g}] veh/h (the [sumo] release rate "
                          "bounds)")
