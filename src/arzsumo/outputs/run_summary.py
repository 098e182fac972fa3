"""The summary of one ``arzsumo run``: a typed record, written as ``summary.json``.

:func:`arzsumo.outputs.bridge.summary` builds it; the console table, ``compare`` and the
sweep table read it. Its blocks are typed where every run has them and mappings where
their keys follow the scenario. :meth:`RunSummary.to_dict` is ``summary.json``, key for
key and in order; the unit of every key is in :data:`arzsumo.schema.RUN_SUMMARY`
(``units_by_key``), and docs/outputs.md describes each. SI: veh, s, m; flows in veh/s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from functools import cached_property
from typing import Any

from arzsumo.schema import RUN_SUMMARY, key_units

#: ``summary.json["kind"]`` of a closed-loop run in SUMO (``arzsumo run``)
KIND = "run"


@dataclass(frozen=True)
class RunIdentity:
    """Which run this is: scenario name and file, package version, SUMO seed, controller."""

    scenario: str
    source: str
    version: str
    seed: int
    controller: str


@dataclass(frozen=True)
class WindowCounts:
    """The control window's meter and controller counts: plan changes (new timings asked
    of the meter), light changes (starts and ends of a green; a yellow is not one),
    controller updates (``triggers``), the release time (s) and the ramp queue's maximum
    (veh)."""

    plan_changes: int
    light_changes: int
    triggers: int
    release_time: float
    max_ramp_queue: int


@dataclass(frozen=True)
class Accounting:
    """SUMO's vehicle accounting at the run's end (None without SUMO's report)."""

    inserted: int | None = None
    requested: int | None = None
    inserted_fraction_main: float | None = None
    waiting: int | None = None
    arrived: int | None = None
    teleports: int | None = None
    collisions: int | None = None
    emergency_braking: int | None = None
    longest_standstill_main: float | None = None


@dataclass(frozen=True)
class RunSummary:
    """One run's summary (module docstring). ``micro`` holds the section's indices from
    the Edie cells (TTT, delay, J_fuel, J_discom, ...), written at the top level of
    ``summary.json`` as well as under ``section``."""

    identity: RunIdentity
    equilibrium: Mapping[str, Any]
    lambda_4: float
    q_nominal: float
    horizon: float
    warmup: Mapping[str, Any]
    counts: WindowCounts
    meter: Mapping[str, Any]
    speed_variance: Mapping[str, float]
    micro: Mapping[str, Any]
    section: Mapping[str, Any]
    network: Mapping[str, Any] | None
    network_whole_run: Mapping[str, Any] | None
    network_whole_demand: Mapping[str, Any] | None
    twin_replay: Mapping[str, Any]
    twin_reference: Mapping[str, Any]
    rmse: Mapping[str, Any]
    rmse_blocks: Mapping[str, Any]
    section_trend: Mapping[str, Any]
    estimation: Mapping[str, Any]
    actuation: Mapping[str, Any]
    twin_status: Mapping[str, Any]
    accounting: Accounting
    placement: str
    wall_time: float
    timings: Mapping[str, float]
    controller_time_per_period: float | None
    settings: Mapping[str, Any]
    complete: bool = True
    disturbance: Mapping[str, Any] | None = None

    def whole_demand_tts_h(self) -> float:
        """Whole-demand total time spent, veh h (NaN unless every loaded vehicle left: the
        drain ran and ended without gridlock)."""
        if not (self.network_whole_demand or {}).get("complete"):
            return math.nan
        return float(self.network_whole_demand["time_spent_s"]["total"]) / 3600.0

    @cached_property
    def _dict(self) -> dict[str, Any]:
        i = self.identity
        out: dict[str, Any] = {
            "kind": KIND, "scenario": i.scenario, "source": i.source, "version": i.version,
            "seed": i.seed, "controller": i.controller, "complete": self.complete,
            "units": "SI: veh, s, m; U and flows in veh/s",
            "equilibrium": dict(self.equilibrium), "lambda_4": self.lambda_4,
            "q_nominal": self.q_nominal, "horizon": self.horizon,
            "warmup": dict(self.warmup), **asdict(self.counts), "meter": dict(self.meter),
            "speed_variance": dict(self.speed_variance), **self.micro,
            "section": dict(self.section), "network": self.network,
            "network_whole_run": self.network_whole_run,
            "network_whole_demand": self.network_whole_demand,
            "twin_replay": self.twin_replay, "twin_reference": self.twin_reference,
            "rmse": self.rmse, "rmse_blocks": self.rmse_blocks,
            "section_trend": self.section_trend, "estimation": self.estimation,
            "actuation": self.actuation, "twin_status": self.twin_status,
            **asdict(self.accounting), "placement": self.placement,
            "wall_time": self.wall_time, "timings": dict(self.timings),
            "controller_time_per_period": self.controller_time_per_period,
            "settings": dict(self.settings), "disturbance": self.disturbance}
        out["units_by_key"] = key_units(out, RUN_SUMMARY)
        return out

    def to_dict(self) -> dict[str, Any]:
        """``summary.json`` (a new dict; its ``units_by_key`` from the schema)."""
        return dict(self._dict)

    def __getitem__(self, key: str) -> Any:
        """``summary.json[key]``: for code that reads the summary as the file has it."""
        return self._dict[key]

    def __contains__(self, key: object) -> bool:
        return key in self._dict
