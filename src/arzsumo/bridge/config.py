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

from arzsumo.errors import ScenarioError, require
from arzsumo.units import veh_h_to_veh_s

CONTROLLERS = ("open", "backstepping", "etc", "observer-etc", "alinea")
RUN_KEYS = {"controller", "warmup_s", "start", "equilibrium", "kernel_cells", "twin_cells",
            "twin_scheme", "smoothing_s", "alinea_target", "alinea_gain_veh_h_per_pct",
            "alinea_saturation_veh_h"}


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
    """Parse the ``[run]`` table of a parsed scenario mapping; ``overrides`` win."""
    from arzsumo.scenarios import scenario_table

    table = scenario_table(data, "run", RUN_KEYS, source)
    where = f"{source} [run]"
    # per % of occupancy -> per unit occupancy is the factor 100
    conv = {"warmup_s": ("warmup", float), "smoothing_s": ("smoothing", float),
            "alinea_target": ("alinea_target", float),
            "alinea_gain_veh_h_per_pct": ("alinea_gain", lambda v: veh_h_to_veh_s(100 * v)),
            "alinea_saturation_veh_h": ("alinea_saturation", veh_h_to_veh_s)}
    values: dict[str, Any] = {}
    for key, value in table.items():
        if key in conv:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: a number")
            name, to_si = conv[key]
            values[name] = float(to_si(value))
        elif key in ("kernel_cells", "twin_cells"):
            if isinstance(value, bool) or not isinstance(value, int):
                raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: an integer")
            values[key] = value
        else:
            if not isinstance(value, str):
                raise ScenarioError(f"{where}: {key} = {value!r} is not allowed: a string")
            values[key] = value
    values.update({k: v for k, v in overrides.items() if v is not None})
    try:
        return RunSettings(**values)
    except ScenarioError as exc:
        raise ScenarioError(f"{where}: {exc}") from None
