"""The ``[run]`` table of a scenario: what ``arzsumo run`` does (human units in key names).

Example::

    [run]
    controller = "etc"          # open, backstepping, etc, observer-etc, alinea
    warmup_s = 150              # nominal meter until control starts
    start = "warmup"            # or "placement": vehicles placed from [initial] at t = 0
    equilibrium = "scenario"    # or "measured": mean of the last 60 s of the warm-up
    kernel_cells = 100          # backstepping kernel grid
    twin_cells = 100            # PDE twin grid (replay and reference)
    twin_scheme = "muscl"       # or "first"
    smoothing_s = 30            # time constant of the measured boundary data fed to the twins
    alinea_target = 0.0         # occupancy target; 0: measured at the end of the warm-up
    alinea_gain_veh_h_per_pct = 70
    alinea_saturation_veh_h = 1800

The control horizon is ``[sumo] horizon_s`` after the warm-up.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

from arzsumo.errors import ArzsumoError, ScenarioError, require
from arzsumo.tables import Key, in_user_terms, read_keys, where
from arzsumo.units import VEH_H_PER_VEH_S

CONTROLLERS = ("open", "backstepping", "etc", "observer-etc", "alinea")
#: [run] key -> RunSettings field (SI), with its unit factor; ALINEA's gain per % of
#: occupancy in veh/h is 100/3600 veh/s per unit occupancy, hence the factor 36
RUN_SPECS: dict[str, Key] = {
    "controller": Key("controller", "string", choices=CONTROLLERS),
    "warmup_s": Key("warmup"),
    "start": Key("start", "string", choices=("warmup", "placement")),
    "equilibrium": Key("equilibrium", "string", choices=("scenario", "measured")),
    "kernel_cells": Key("kernel_cells", "integer"),
    "twin_cells": Key("twin_cells", "integer"),
    "twin_scheme": Key("twin_scheme", "string", choices=("first", "muscl")),
    "smoothing_s": Key("smoothing"),
    "alinea_target": Key("alinea_target"),
    "alinea_gain_veh_h_per_pct": Key("alinea_gain", factor=VEH_H_PER_VEH_S / 100,
                                     allowed="a gain > 0 veh/h per % of occupancy"),
    "alinea_saturation_veh_h": Key("alinea_saturation", factor=VEH_H_PER_VEH_S,
                                   allowed="a flow > 0 veh/h"),
}
RUN_KEYS = set(RUN_SPECS)


@dataclass(frozen=True)
class RunSettings:
    """Settings of one co-simulation (SI; ALINEA gain in veh/s per unit occupancy)."""

    controller: str = "etc"
    warmup: float = 150.0
    start: str = "warmup"
    equilibrium: str = "scenario"
    kernel_cells: int = 100
    twin_cells: int = 100
    twin_scheme: str = "muscl"
    smoothing: float = 30.0
    alinea_target: float = 0.0
    alinea_gain: float = 7000.0 / 3600.0
    alinea_saturation: float = 1800.0 / 3600.0

    def __post_init__(self) -> None:
        def check(ok: bool, name: str, allowed: str) -> None:
            require(ok, name, getattr(self, name), allowed, ScenarioError)

        check(self.controller in CONTROLLERS, "controller", f"one of {', '.join(CONTROLLERS)}")
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
        check(0 <= self.alinea_target < 10, "alinea_target",
              "an occupancy fraction >= 0 (0: measured)")
        check(self.alinea_gain > 0, "alinea_gain", "> 0")
        check(self.alinea_saturation > 0, "alinea_saturation", "> 0")

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def run_settings_from_dict(data: Mapping[str, Any], source: str = "<dict>",
                           **overrides: Any) -> RunSettings:
    """Parse the ``[run]`` table of a parsed scenario mapping; ``overrides`` win.

    Errors name the file, ``[run]``, the key and the value as written; an error about an
    overridden field names ``--field`` (the CLI option) instead.
    """
    from arzsumo.scenarios import scenario_table

    table = scenario_table(data, "run", RUN_KEYS, source)
    at = where(source, "run")
    values = read_keys(table, RUN_SPECS, at)
    given = {k: v for k, v in overrides.items() if v is not None}
    values.update(given)
    try:
        return RunSettings(**values)
    except ArzsumoError as exc:
        if exc.field in given:
            raise type(exc)(f"--{exc.field} = {exc.value} is not allowed: "
                            f"{exc.allowed}") from None
        raise in_user_terms(exc, at, table, RUN_SPECS) from None
