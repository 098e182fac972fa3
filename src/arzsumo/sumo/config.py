"""Settings of a SUMO run (:class:`SumoConfig`, SI: s, m, veh/s; the ``[sumo]`` keys that
set them, in the units their names state, and the conversions: :mod:`arzsumo.scenario.sumo`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from typing import Any

from arzsumo.errors import ScenarioError, require
from arzsumo.sumo.car_following import ATTRIBUTES, check_values
from arzsumo.sumo.layout import RoadLayout
from arzsumo.sumo.network import NetworkSpec

HV_MODELS = ("Krauss", "IDM", "EIDM")
#: Width of the mainline lane, m (the network's).
LANE_WIDTH = 6.5
AV_MODELS = ("ACC", "CACC")
#: SUMO's latAlignment values a vehicle type may take (the sublane model)
LAT_ALIGNMENTS = ("arbitrary", "center", "right", "left", "nice", "compact")
#: mainline lateral insertion: the fixed columns (:mod:`arzsumo.sumo.demand`), or SUMO's
#: own departPosLat values
DEPART_POS_LAT = ("columns", "random", "random_free", "free", "center")
#: How the ramp meter is realised (:mod:`arzsumo.sumo.meter`, :mod:`arzsumo.sumo.meter_release`)
METER_MODES = ("fixed_cycle", "one_per_green")


#: jam spacing of a stored ramp vehicle, m: an HV's length + minGap at the model's default
#: spacing s_h = 8 m (:mod:`arzsumo.sumo.vtypes`)
RAMP_JAM_SPACING = 8.0


def _require(ok: bool, field: str, value: object, allowed: str) -> None:
    require(ok, field, value, allowed, ScenarioError)


def ramp_capacity(length: float | None = None, spacing: float = RAMP_JAM_SPACING) -> int:
    """Vehicles a ramp of ``length`` (m; default: ``ramp_up`` of the network, 300 m) holds
    at jam spacing ``spacing`` (m): 37 on the shipped network."""
    ramp = NetworkSpec().ramp_length if length is None else length
    return int(ramp // spacing)


@dataclass(frozen=True)
class SumoConfig:
    """One SUMO run: numerics, demand, measurement grid and ramp meter (SI units).

    Every field but ``layout`` is a ``[sumo]`` key: docs/scenarios.md, "[sumo]", gives
    each one's meaning, default and range (its "SI field" column names the field);
    :mod:`arzsumo.sumo.car_following` says which model reads which car-following field.

    * ``ramp_storage`` = -1 (the default) becomes what the ramp holds at jam spacing,
      :func:`ramp_capacity`;
    * ``hv_max_speed``, ``av_max_speed``: a scenario whose model is identified from SUMO
      states the speeds its SUMO runs used, so that the fitted V_i do not change the
      traffic they were fitted to;
    * ``layout``: the user's network of a ``[network]`` table, checked by
      :func:`arzsumo.sumo.user_network.read_layout`; None (default): the shipped one.
    """

    step_length: float = 0.1
    lateral_resolution: float = 0.5
    seed: int = 42
    horizon: float = 450.0
    demand_h: float = 4104.0 / 3600.0
    demand_a: float = 1560.0 / 3600.0
    ramp_demand: float = 1200.0 / 3600.0
    ramp_av_share: float = 0.0
    cell_length: float = 50.0
    control_period: float = 1.0
    meter_cycle: float = 6.0
    min_green: float = 1.0
    min_red: float = 1.0
    green_share: float = 0.5
    green_share_min: float = 0.0
    green_share_max: float = 1.0
    ramp_storage: int = -1
    drain_max: float = 0.0
    meter_mode: str = "fixed_cycle"
    meter_clearance: float = 0.0
    max_green: float = 3.0
    release_rate: float = 600.0 / 3600.0
    release_rate_min: float = 240.0 / 3600.0
    release_rate_max: float = 900.0 / 3600.0
    time_to_teleport: float = -1.0
    hv_model: str = "Krauss"
    hv_sigma: float = 0.5
    av_model: str = "ACC"
    hv_accel: float = 2.6
    hv_decel: float = 4.5
    av_accel: float = 2.0
    av_decel: float = 4.5
    hv_sigma_step: float | None = None
    hv_delta: float | None = None
    hv_stepping: float | None = None
    hv_reaction: float | None = None
    hv_sigma_error: float | None = None
    hv_sigma_gap: float | None = None
    hv_sigma_leader: float | None = None
    av_speed_gain: float | None = None
    av_gap_gain_space: float | None = None
    av_gap_gain_speed: float | None = None
    av_gap_gain_gap: float | None = None
    av_gap_gain_gap_dot: float | None = None
    min_gap_lat: float = 0.15
    lat_alignment: str = "arbitrary"
    lc_sublane: float = 1.0
    lc_speed_gain: float = 0.5
    lc_pushy: float = 0.2
    lc_assertive: float | None = None
    lc_impatience: float | None = None
    depart_pos_lat: str = "columns"
    hv_tau: float = 1.0
    hv_action_step: float = 0.0
    down_speed: float = 50.0 / 3.6
    down_length: float = 500.0
    meter_curve: str = ""
    approach_length: float = 0.0
    approach_piece: float = 0.0
    demand_scale: float = 1.0
    hv_max_speed: float = 0.0
    av_max_speed: float = 0.0
    fill_duration: float = 0.0
    fill_demand_h: float = 0.0
    fill_demand_a: float = 0.0
    eager_insert: bool = True
    collision_check: bool = False
    fcd: bool = False
    layout: RoadLayout | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self._each(("step_length", "lateral_resolution", "horizon", "cell_length",
                    "control_period", "meter_cycle", "min_gap_lat", "max_green",
                    "release_rate", "release_rate_min", "release_rate_max", "hv_tau",
                    "down_speed", "down_length", "demand_scale"),
                   lambda v: math.isfinite(v) and v > 0, "a finite number greater than 0")
        self._each(("demand_h", "demand_a", "ramp_demand", "min_green", "min_red",
                    "approach_length", "approach_piece", "meter_clearance",
                    "fill_duration", "drain_max", "fill_demand_h", "fill_demand_a",
                    "hv_max_speed", "av_max_speed",
                    "lc_sublane", "lc_speed_gain", "hv_action_step"),
                   lambda v: math.isfinite(v) and v >= 0, "a finite number of at least 0")
        self._each(("ramp_av_share", "green_share", "hv_sigma", "green_share_min",
                    "green_share_max", "lc_pushy"),
                   lambda v: 0.0 <= v <= 1.0, "a number in [0, 1]")
        self._check_gap_acceptance()
        _require(self.green_share_min <= self.green_share_max, "green_share_min",
                 self.green_share_min, f"at most green_share_max = {self.green_share_max}")
        # a cell holds a vehicle or more; shorter cells only multiply the work
        _require(self.cell_length >= 1.0, "cell_length", self.cell_length, "at least 1 m")
        _require(self.step_length <= 1.0, "step_length", self.step_length, "at most 1 s")
        self._check_resolution()
        # a shorter run holds no complete control period: nothing measured, NaN summaries
        _require(self.horizon >= self.control_period, "horizon", self.horizon,
                 f"at least one control period (control_period = {self.control_period} s)")
        ratio = self.control_period / self.step_length
        _require(abs(ratio - round(ratio)) < 1e-9, "control_period", self.control_period,
                 f"a multiple of step_length = {self.step_length} s")
        _require(self.min_green + self.min_red <= self.meter_cycle, "min_green + min_red",
                 self.min_green + self.min_red, f"at most meter_cycle = {self.meter_cycle} s")
        self._check_meter()
        _require(isinstance(self.seed, int) and not isinstance(self.seed, bool)
                 and 0 <= self.seed < 2**31, "seed", self.seed, "an integer in [0, 2^31)")
        self._resolve_storage()
        _require(self.time_to_teleport == -1 or self.time_to_teleport > 0, "time_to_teleport",
                 self.time_to_teleport, "-1 (off) or a time > 0 s")
        for name in ("fcd", "eager_insert", "collision_check"):
            _require(isinstance(getattr(self, name), bool), name, getattr(self, name),
                     "true or false")
        self._check_behaviour()

    def _each(self, names: tuple[str, ...], ok: Callable[[float], bool],
              allowed: str) -> None:
        """Each field of ``names`` is a number for which ``ok`` holds."""
        for name in names:
            v = getattr(self, name)
            _require(isinstance(v, int | float) and ok(v), name, v, allowed)

    def _check_resolution(self) -> None:
        """The sublane width divides the lane (the section's lanes on a user's network
        that runs the sublane model)."""
        widths = (LANE_WIDTH,) if self.layout is None else \
            self.layout.lane_widths if self.layout.sublane else ()
        for width in sorted(set(widths)):
            subl = width / self.lateral_resolution
            _require(abs(subl - round(subl)) < 1e-6, "lateral_resolution",
                     self.lateral_resolution,
                     f"a width dividing the {width:g} m lane, e.g. 0.5 or 0.25")

    @property
    def collision_options(self) -> dict[str, str]:
        """SUMO's collision options of :attr:`collision_check` (option -> value)."""
        if self.collision_check:
            return {"collision.action": "warn", "collision.check-junctions": "true"}
        return {"collision.action": "none"}

    def _check_behaviour(self) -> None:
        """The car-following models, the lateral behaviour's choices, the HVs' action step."""
        _require(self.hv_model in HV_MODELS, "hv_model", self.hv_model, " or ".join(HV_MODELS))
        _require(self.av_model in AV_MODELS, "av_model", self.av_model, " or ".join(AV_MODELS))
        check_values({a.field: getattr(self, a.field) for a in ATTRIBUTES})
        _require(self.lat_alignment in LAT_ALIGNMENTS, "lat_alignment", self.lat_alignment,
                 ", ".join(LAT_ALIGNMENTS))
        _require(self.depart_pos_lat in DEPART_POS_LAT, "depart_pos_lat", self.depart_pos_lat,
                 ", ".join(DEPART_POS_LAT))
        if self.hv_action_step > 0:
            k = self.hv_action_step / self.step_length
            _require(round(k) >= 1 and abs(k - round(k)) < 1e-9, "hv_action_step",
                     self.hv_action_step,
                     f"0 (every step) or a multiple of step_length = {self.step_length} s")

    def _resolve_storage(self) -> None:
        """Check ``ramp_storage``; -1 becomes what the ramp holds (:func:`ramp_capacity`)."""
        _require(isinstance(self.ramp_storage, int) and self.ramp_storage >= -1,
                 "ramp_storage", self.ramp_storage,
                 "an integer >= 0 (0 = no queue override; -1: what the ramp holds)")
        if self.ramp_storage == -1:
            ramp = None if self.layout is None else self.layout.ramp_length
            object.__setattr__(self, "ramp_storage", ramp_capacity(ramp))

    def _check_meter(self) -> None:
        """The meter's mode and timings fit together (clearance inside the cycle, release
        rates ordered, the fastest release cycle long enough for its phases)."""
        _require(self.meter_mode in METER_MODES, "meter_mode", self.meter_mode,
                 " or ".join(METER_MODES))
        phases = self.min_green + self.meter_clearance + self.min_red
        if self.meter_clearance > 0:
            _require(phases <= self.meter_cycle + 1e-9, "min_green + meter_clearance + min_red",
                     phases, f"at most meter_cycle = {self.meter_cycle} s")
        _require(self.release_rate_min <= self.release_rate <= self.release_rate_max,
                 "release_rate", self.release_rate,
                 f"a rate in [release_rate_min, release_rate_max] = [{self.release_rate_min}, "
                 f"{self.release_rate_max}] veh/s")
        _require(self.min_green <= self.max_green, "max_green", self.max_green,
                 f"at least min_green = {self.min_green} s")
        if self.meter_mode == "one_per_green":
            _require(phases <= 1.0 / self.release_rate_max + 1e-9,
                     "min_green + meter_clearance + min_red", phases,
                     f"at most the cycle 1 / release_rate_max = {1 / self.release_rate_max:.3g} "
                     "s of one_per_green")

    def car_following(self, cls: str) -> dict[str, float | None]:
        """The car-following fields of class ``cls`` ("hv" or "av") by field name."""
        return {a.field: getattr(self, a.field) for a in ATTRIBUTES if a.cls == cls}

    @property
    def steps_per_period(self) -> int:
        """SUMO steps per control period."""
        return round(self.control_period / self.step_length)

    def _check_gap_acceptance(self) -> None:
        """``lc_assertive`` > 0 and ``lc_impatience`` in [0, 1] where set."""
        if self.lc_assertive is not None:
            _require(math.isfinite(self.lc_assertive) and self.lc_assertive > 0,
                     "lc_assertive", self.lc_assertive, "a finite number above 0")
        if self.lc_impatience is not None:
            _require(isinstance(self.lc_impatience, int | float)
                     and 0.0 <= self.lc_impatience <= 1.0, "lc_impatience",
                     self.lc_impatience, "a number in [0, 1]")

    def with_(self, **changes: Any) -> SumoConfig:
        """A copy with some fields changed (validated again)."""
        unknown = set(changes) - {f.name for f in fields(self)}
        if unknown:
            raise ScenarioError(f"unknown SUMO setting(s) {sorted(unknown)}; allowed: "
                                f"{', '.join(f.name for f in fields(self))}")
        return replace(self, **changes)
