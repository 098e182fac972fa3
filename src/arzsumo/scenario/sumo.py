"""The ``[sumo]`` section: how ``arzsumo run`` (and ``calibrate``) drive SUMO.

Every key, its unit and its conversion to the SI field of
:class:`arzsumo.sumo.config.SumoConfig`: :data:`SUMO_KEYS` (docs/scenarios.md). A relative
``meter_curve`` is read relative to the scenario file.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from arzsumo.errors import ScenarioError
from arzsumo.sumo.car_following import ignored, readers
from arzsumo.sumo.config import (
    AV_MODELS,
    DEPART_POS_LAT,
    HV_MODELS,
    LAT_ALIGNMENTS,
    METER_MODES,
    SumoConfig,
)
from arzsumo.tables import Key, read_section, written
from arzsumo.units import KMH_PER_MS, VEH_H_PER_VEH_S

_DEMAND = "a demand >= 0 veh/h"
_ACC = "an acceleration > 0 m/s^2"
#: the car-following keys (arzsumo.sumo.car_following says which model reads which)
CAR_FOLLOWING_KEYS: dict[str, Key] = {
    "hv_accel_m_s2": Key("hv_accel", unit="m/s^2", allowed=_ACC,
                         doc="HVs' largest acceleration (SUMO accel; every model)"),
    "hv_decel_m_s2": Key("hv_decel", unit="m/s^2", allowed=_ACC,
                         doc="HVs' comfortable deceleration (SUMO decel; every model)"),
    "hv_sigma_step_s": Key("hv_sigma_step", unit="s",
                           doc="Krauss: how often the driver imperfection is redrawn (SUMO "
                               "sigmaStep); default every step, which dilutes sigma at "
                               "small steps"),
    "hv_delta": Key("hv_delta", doc="IDM, EIDM: acceleration exponent (SUMO delta, "
                                    "default 4)"),
    "hv_stepping_s": Key("hv_stepping", unit="s",
                         doc="IDM, EIDM: internal step of the follow speed (SUMO stepping, "
                             "default 0.25 s)"),
    "hv_reaction_s": Key("hv_reaction", unit="s",
                         doc="EIDM: reaction time (SUMO treaction, default 0.5 s)"),
    "hv_sigma_error": Key("hv_sigma_error", doc="EIDM: error of the own speed estimate "
                                                "(SUMO sigmaerror, default 0.1)"),
    "hv_sigma_gap": Key("hv_sigma_gap", doc="EIDM: error of the gap estimate (SUMO "
                                            "sigmagap, default 0.1)"),
    "hv_sigma_leader": Key("hv_sigma_leader", doc="EIDM: error of the leader's speed "
                                                  "estimate (SUMO sigmaleader, default "
                                                  "0.02)"),
    "av_accel_m_s2": Key("av_accel", unit="m/s^2", allowed=_ACC,
                         doc="AVs' largest acceleration (SUMO accel)"),
    "av_decel_m_s2": Key("av_decel", unit="m/s^2", allowed=_ACC,
                         doc="AVs' comfortable deceleration (SUMO decel)"),
    "av_speed_gain": Key("av_speed_gain", unit="1/s",
                         doc="ACC, CACC: gain of the speed-control mode (SUMO "
                             "speedControlGain, default -0.4)"),
    "av_gap_gain_space": Key("av_gap_gain_space", unit="1/s^2",
                             doc="ACC, CACC: gap-control gain on the spacing error (SUMO "
                                 "gapControlGainSpace, default 0.23)"),
    "av_gap_gain_speed": Key("av_gap_gain_speed", unit="1/s",
                             doc="ACC, CACC: gap-control gain on the speed difference (SUMO "
                                 "gapControlGainSpeed, default 0.07)"),
    "av_gap_gain_gap": Key("av_gap_gain_gap", doc="CACC: gap-control gain on the gap error "
                                                  "(SUMO gapControlGainGap, default 0.45)"),
    "av_gap_gain_gap_dot": Key("av_gap_gain_gap_dot",
                               doc="CACC: gap-control gain on the gap error's rate (SUMO "
                                   "gapControlGainGapDot, default 0.0125)"),
}
_RATE = ("a rate > 0 veh/h, with release_rate_min_veh_h <= release_rate_veh_h <= "
         "release_rate_max_veh_h")
#: [sumo] key -> SumoConfig field (SI), with its unit factor
SUMO_KEYS: dict[str, Key] = {
    "step_length_s": Key("step_length", unit="s", doc="SUMO time step (ACC/CACC need small "
                                                      "steps), at most 1 s"),
    "lateral_resolution_m": Key("lateral_resolution", unit="m",
                                doc="sublane width; divides the 6.5 m lane"),
    "seed": Key("seed", "integer", doc="SUMO random seed, in [0, 2^31); also draws an "
                                       "[initial] kind = \"random\" placement"),
    "horizon_s": Key("horizon", unit="s", doc="control horizon after the warm-up "
                                              "(`arzsumo run --horizon`)"),
    "demand_h_veh_h": Key("demand_h", factor=VEH_H_PER_VEH_S, allowed=_DEMAND, unit="veh/h",
                          doc="HV flow requested at the mainline entrance"),
    "demand_a_veh_h": Key("demand_a", factor=VEH_H_PER_VEH_S, allowed=_DEMAND, unit="veh/h",
                          doc="AV flow requested at the mainline entrance"),
    "ramp_demand_veh_h": Key("ramp_demand", factor=VEH_H_PER_VEH_S, allowed=_DEMAND,
                             unit="veh/h", doc="flow requested on the on-ramp"),
    "ramp_av_share": Key("ramp_av_share", doc="share of AVs in the ramp demand, in [0, 1]"),
    "cell_length_m": Key("cell_length", unit="m",
                         doc="measurement cell length (divides the road length)"),
    "control_period_s": Key("control_period", unit="s",
                            doc="measurement window and meter update period of `arzsumo "
                                "run` (a multiple of the step)"),
    "meter_cycle_s": Key("meter_cycle", unit="s", doc="ramp meter signal cycle"),
    "min_green_s": Key("min_green", unit="s", doc="minimum green time per cycle"),
    "min_red_s": Key("min_red", unit="s", doc="minimum red time per cycle"),
    "green_share": Key("green_share", doc="nominal green share of the cycle (open loop)"),
    "green_share_min": Key("green_share_min", doc="lowest commanded green share"),
    "green_share_max": Key("green_share_max", doc="highest commanded green share"),
    "ramp_storage_veh": Key("ramp_storage", "integer", unit="veh",
                            doc="vehicles the ramp stores: while the ramp queue exceeds it "
                                "the meter releases at its largest rate (fixed_cycle: "
                                "green), for every controller; 0 disables the override; "
                                "default: what ramp_up holds at jam spacing (37)"),
    "drain_max_s": Key("drain_max", unit="s",
                       doc="after the control window no vehicle is requested and the run "
                           "goes on, the meter at its largest rate, until every loaded "
                           "vehicle has left (network_whole_demand), at most this long; "
                           "0 ends the run with the window"),
    "meter_mode": Key("meter_mode", "string", choices=METER_MODES,
                      doc="ramp meter realisation: green share of a fixed cycle, or one "
                          "vehicle per green at a release rate"),
    "meter_clearance_s": Key("meter_clearance", unit="s",
                             doc="yellow before every red of the meter; 0 switches green "
                                 "to red"),
    "max_green_s": Key("max_green", unit="s",
                       doc="one_per_green: longest green (min_green_s extended until the "
                           "head vehicle crosses the stop line)"),
    "release_rate_veh_h": Key("release_rate", factor=VEH_H_PER_VEH_S, allowed=_RATE,
                              unit="veh/h", doc="one_per_green: release rate of the nominal "
                                                "plan (open loop); a command U sets rate - U"),
    "release_rate_min_veh_h": Key("release_rate_min", factor=VEH_H_PER_VEH_S, allowed=_RATE,
                                  unit="veh/h", doc="one_per_green: lowest release rate"),
    "release_rate_max_veh_h": Key("release_rate_max", factor=VEH_H_PER_VEH_S, allowed=_RATE,
                                  unit="veh/h", doc="one_per_green: highest release rate "
                                                    "(also the queue override's)"),
    "time_to_teleport_s": Key("time_to_teleport", unit="s",
                              doc="SUMO's --time-to-teleport; -1 disables teleports"),
    "hv_model": Key("hv_model", "string", choices=HV_MODELS, doc="HV car-following model"),
    "hv_sigma": Key("hv_sigma", doc="Krauss: HV driver imperfection, in [0, 1] (SUMO sigma)"),
    "av_model": Key("av_model", "string", choices=AV_MODELS, doc="AV car-following model"),
    "min_gap_lat_m": Key("min_gap_lat", unit="m", doc="lateral gap kept by both classes"),
    "lat_alignment": Key("lat_alignment", "string", choices=LAT_ALIGNMENTS,
                         doc="both classes' preferred lateral position (SUMO latAlignment)"),
    "lc_sublane": Key("lc_sublane", doc="eagerness for sublane changes (SUMO lcSublane), "
                                        ">= 0"),
    "lc_speed_gain": Key("lc_speed_gain", doc="eagerness for changes that gain speed (SUMO "
                                              "lcSpeedGain), >= 0"),
    "lc_pushy": Key("lc_pushy", doc="willingness to encroach laterally (SUMO lcPushy), in "
                                    "[0, 1]"),
    "lc_assertive": Key("lc_assertive", doc="both classes: willingness to accept smaller "
                                            "gaps when changing lanes, > 0; SUMO divides "
                                            "the required gap by it (SUMO lcAssertive, "
                                            "default 1; unset: not written)"),
    "lc_impatience": Key("lc_impatience", doc="both classes: growth of the willingness to "
                                              "accept smaller gaps while waiting to change "
                                              "lanes, in [0, 1] (SUMO lcImpatience, "
                                              "default 0; unset: not written)"),
    "depart_pos_lat": Key("depart_pos_lat", "string", choices=DEPART_POS_LAT,
                          doc="mainline lateral insertion: fixed columns (HVs at the edges, "
                              "AVs at the centre) or a SUMO departPosLat"),
    "hv_tau_s": Key("hv_tau", unit="s", doc="HVs' desired time headway (SUMO tau)"),
    **CAR_FOLLOWING_KEYS,
    "hv_action_step_s": Key("hv_action_step", unit="s",
                            doc="HVs' action step (SUMO actionStepLength, a reaction time); "
                                "0: every step"),
    "down_speed_kmh": Key("down_speed", factor=KMH_PER_MS, unit="km/h",
                          doc="speed limit of the downstream bottleneck edge down"),
    "down_length_m": Key("down_length", unit="m", doc="length of the downstream edge down"),
    "meter_curve": Key("meter_curve", "string",
                       doc="meter_curve.toml of `arzsumo calibrate`, relative to the scenario "
                           "file; \"\" keeps the built-in curve"),
    "approach_length_m": Key("approach_length", unit="m",
                             doc="approach (buffer) edge before x = 0 where mainline vehicles "
                                 "are inserted and may queue; 0 inserts them at x = 0 on the "
                                 "shipped network"),
    "demand_scale": Key("demand_scale",
                        doc="SUMO --scale: the demand, route files included, loaded this "
                            "many times on average (1: as written)"),
    "approach_piece_m": Key("approach_piece", unit="m",
                            doc="longest edge the approach is cut into (the same road; "
                                "SUMO's sublane step costs less on short edges); 0: one "
                                "edge"),
    "hv_max_speed_kmh": Key("hv_max_speed", factor=KMH_PER_MS, unit="km/h",
                            doc="HV maxSpeed in SUMO; 0: the model's V_h"),
    "av_max_speed_kmh": Key("av_max_speed", factor=KMH_PER_MS, unit="km/h",
                            doc="AV maxSpeed in SUMO; 0: the model's V_a"),
    "fill_s": Key("fill_duration", unit="s",
                  doc="fill phase from t = 0 of SUMO with the fill demands below; 0: none"),
    "fill_demand_h_veh_h": Key("fill_demand_h", factor=VEH_H_PER_VEH_S, allowed=_DEMAND,
                               unit="veh/h", doc="HV flow requested at the mainline "
                                                 "entrance during the fill phase"),
    "fill_demand_a_veh_h": Key("fill_demand_a", factor=VEH_H_PER_VEH_S, allowed=_DEMAND,
                               unit="veh/h", doc="AV flow requested at the mainline "
                                                 "entrance during the fill phase"),
    "eager_insert": Key("eager_insert", "bool",
                        doc="try every vehicle waiting for insertion every step (SUMO "
                            "--eager-insert), not only the first of each edge"),
    "collision_check": Key("collision_check", "bool",
                           doc="SUMO's collision detection (--collision.action warn, at "
                               "junctions too), to count collisions; off: it changes no "
                               "vehicle and costs a third of the sublane step"),
    "fcd": Key("fcd", "bool", doc="write SUMO's trajectories of every vehicle every step "
                                  "(fcd.xml.gz in the run directory; `arzsumo run --fcd`)"),
}


def refuse_ignored_car_following(table: Mapping[str, Any], at: str, cfg: SumoConfig) -> None:
    """Refuse a car-following key that the chosen model does not read: SUMO would ignore
    it without a word (``hv_sigma`` under IDM)."""
    by_field = {SUMO_KEYS[k].field: k for k in table if k in SUMO_KEYS}
    for f in ignored(by_field, cfg.hv_model, cfg.av_model):
        key, cls = by_field[f], f[:2]
        model = cfg.hv_model if cls == "hv" else cfg.av_model
        names = " or ".join(written(m) for m in readers(f))
        raise ScenarioError(
            f"{at} {key} = {written(table[key])} is not read by {cls}_model = "
            f"{written(model)} (SUMO would ignore it); allowed: remove it, or set "
            f"{cls}_model = {names}")


#: [sumo] keys that act under one meter_mode only: under the other they would be ignored
MODE_ONLY_KEYS: dict[str, tuple[str, ...]] = {
    "fixed_cycle": ("green_share", "green_share_min", "green_share_max", "meter_cycle_s"),
    "one_per_green": ("release_rate_veh_h", "release_rate_min_veh_h", "release_rate_max_veh_h",
                      "max_green_s"),
}


def refuse_inert_meter_keys(table: Mapping[str, Any], at: str, mode: str) -> None:
    """Refuse a key of ``table`` that the meter realisation ``mode`` would ignore (a user
    who sets ``green_share = 0`` under one per green expecting a red meter would get the
    nominal release rate)."""
    for other, keys in MODE_ONLY_KEYS.items():
        bad = [k for k in keys if k in table and other != mode]
        if bad:
            raise ScenarioError(
                f"{at} {bad[0]} = {written(table[bad[0]])} is not allowed with meter_mode = "
                f"{written(mode)}: it acts only under meter_mode = {written(other)}; "
                f"allowed: remove it, or set meter_mode = {written(other)}")


def sumo_section(table: Mapping[str, Any], at: str, source: str = "<dict>") -> SumoConfig:
    """The SumoConfig of a ``[sumo]`` table (keys already checked against SUMO_KEYS).

    A relative ``meter_curve`` is read from the directory of ``source`` (the working
    directory for a scenario not read from a file) and made absolute; the file must exist.
    """
    cfg = read_section(SumoConfig, table, SUMO_KEYS, at)
    refuse_inert_meter_keys(table, at, cfg.meter_mode)
    refuse_ignored_car_following(table, at, cfg)
    if not cfg.meter_curve:
        return cfg
    path = Path(cfg.meter_curve).expanduser()
    if not path.is_absolute() and Path(source).is_file():
        path = Path(source).parent / path
    if not path.is_file():
        raise ScenarioError(f"{at} meter_curve = {written(cfg.meter_curve)} is not allowed: "
                            f"there is no file {str(path)!r}; allowed: a meter_curve.toml of "
                            "`arzsumo calibrate`, relative to the scenario file")
    return cfg.with_(meter_curve=str(path.resolve()))


def anchor_meter_curve(data: Mapping[str, Any], base_dir: Path) -> dict[str, Any]:
    """A copy of a parsed scenario whose relative ``[sumo] meter_curve`` is made absolute
    against ``base_dir`` (the directory of the file it was written in)."""
    out = copy.deepcopy(dict(data))
    table = out.get("sumo")
    value = table.get("meter_curve") if isinstance(table, dict) else None
    if isinstance(value, str) and value and not Path(value).expanduser().is_absolute():
        table["meter_curve"] = str(base_dir / value)
    return out
