"""Demand: the route file with vehicle types, routes, class flows and initial vehicles.

Mainline flows enter at x = 0 with ``departSpeed="desired"`` in fixed lateral columns
(HVs alternating between the lane's two edges, ``hv_0`` and ``hv_1``, AVs at its centre,
``av_0``; why: docs/sumo.md, "Vehicle types and demand"); ramp flows ``ramp_hv`` and
``ramp_av`` at the start of ``ramp_up``. With ``cfg.approach_length > 0`` the mainline
route ``r_main`` starts on ``approach``; initial vehicles, placed on ``main``, then follow
``r_section`` (``main`` onwards).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from arzsumo.errors import ScenarioError
from arzsumo.io import atomic_file
from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network import DOWN, MAIN, MERGE, RAMP_DN, RAMP_UP, approach_edges, xml_file
from arzsumo.sumo.vtypes import AV_TYPE, HV_TYPE, vehicle_types

ROUTE_MAIN, ROUTE_RAMP, ROUTE_SECTION = "r_main", "r_ramp", "r_section"


@dataclass(frozen=True)
class Flow:
    """An evenly spaced flow: id, vType, route, rate (veh/s), begin and end (s)."""

    id: str
    type: str
    route: str
    rate: float
    begin: float
    end: float
    lat: str = "center"
    #: departSpeed; None: "desired" on the mainline (free road at x = 0), "max" on the ramp
    depart_speed: str | None = None
    #: departLane: the one lane of the shipped network, "free" on a user's network
    depart_lane: str = "0"

    @property
    def period(self) -> float:
        """Headway between departures, s."""
        return 1.0 / self.rate

    def to_xml(self) -> str:
        speed = self.depart_speed or ("desired" if self.route == ROUTE_MAIN else "max")
        attrs = {"id": self.id, "type": self.type, "route": self.route,
                 "begin": f"{self.begin:.6g}", "end": f"{self.end:.6g}",
                 "period": f"{self.period:.9g}", "departLane": self.depart_lane,
                 "departPos": "base", "departPosLat": self.lat, "departSpeed": speed}
        return "<flow " + " ".join(f"{k}={quoteattr(v)}" for k, v in attrs.items()) + "/>"


@dataclass(frozen=True)
class InitialVehicle:
    """A vehicle placed at t = 0 (front position ``pos`` on ``main``, m; speed m/s; lateral m)."""

    id: str
    type: str
    pos: float
    speed: float
    lat: float

    def to_xml(self, route: str = ROUTE_MAIN) -> str:
        attrs = {"id": self.id, "type": self.type, "route": route, "depart": "0",
                 "departLane": "0", "departPos": f"{self.pos:.3f}",
                 "departSpeed": f"{self.speed:.3f}", "departPosLat": f"{self.lat:.3f}",
                 "insertionChecks": "none"}
        return "<vehicle " + " ".join(f"{k}={quoteattr(v)}" for k, v in attrs.items()) + "/>"


#: Lateral insertion columns on the mainline: HV columns, AV columns.
HV_COLUMNS, AV_COLUMNS = 2, 1


def insertion_columns(road_width: float, vehicle_width: float, n: int) -> list[float]:
    """Lateral offsets (m, from the lane centre) of ``n`` columns evenly from one lane edge
    to the other (``n = 1``: the centre)."""
    edge = max(0.0, (road_width - vehicle_width) / 2.0)
    return [0.0] if n == 1 else list(np.linspace(-edge, edge, n))


def _columns(fid: str, vtype: str, rate: float, lats: Sequence[float | str], end: float,
             begin: float = 0.0) -> list[Flow]:
    n = len(lats)
    return [Flow(f"{fid}_{i}", vtype, ROUTE_MAIN, rate / n,
                 begin + (i / rate if rate > 0 else 0.0), end,
                 lat if isinstance(lat, str) else f"{lat:.3f}")
            for i, lat in enumerate(lats)]


def _mainline(fid: str, vtype: str, lats: Sequence[float | str], hold: float, fill: float,
              cfg: SumoConfig) -> list[Flow]:
    """A class's mainline columns: ``fill`` veh/s until ``cfg.fill_duration``, then ``hold``."""
    if cfg.fill_duration <= 0:
        return _columns(fid, vtype, hold, lats, cfg.horizon)
    until = min(cfg.fill_duration, cfg.horizon)
    fill_flows = _columns(f"{fid}_fill", vtype, fill, lats, until)
    if until >= cfg.horizon:          # a run shorter than the fill phase has no hold flows
        return fill_flows
    return [*fill_flows, *_columns(fid, vtype, hold, lats, cfg.horizon, begin=until)]


def demand_flows(cfg: SumoConfig, road_width: float = 6.5,
                 vehicle_width: float = 2.0) -> list[Flow]:
    """The class flows of ``cfg``, mainline flows split into columns (zero rates left out;
    one flow per class when ``cfg.depart_pos_lat`` is a SUMO value); with a fill phase two
    per column, the fill demand up to ``cfg.fill_duration``, then the hold demand."""
    ramp_a = cfg.ramp_demand * cfg.ramp_av_share
    hv_lats: Sequence[float | str] = insertion_columns(road_width, vehicle_width, HV_COLUMNS)
    av_lats: Sequence[float | str] = [0.0] * AV_COLUMNS
    if cfg.depart_pos_lat != "columns":   # SUMO places every mainline vehicle itself
        hv_lats = av_lats = [cfg.depart_pos_lat]
    flows = [*_mainline("hv", HV_TYPE, hv_lats, cfg.demand_h, cfg.fill_demand_h, cfg),
             *_mainline("av", AV_TYPE, av_lats, cfg.demand_a, cfg.fill_demand_a, cfg),
             Flow("ramp_hv", HV_TYPE, ROUTE_RAMP, cfg.ramp_demand - ramp_a, 0.0, cfg.horizon),
             Flow("ramp_av", AV_TYPE, ROUTE_RAMP, ramp_a, 0.0, cfg.horizon)]
    return [f for f in flows if f.rate > 1e-12 and f.begin < f.end]   # SUMO refuses empty flows


def check_columns(road_width: float, vehicle_width: float, resolution: float,
                  offsets: Sequence[float]) -> None:
    """Raise unless vehicles in the lateral ``offsets`` (m) occupy disjoint sublanes.

    SUMO's sublane model blocks an insertion whenever another vehicle occupies one of the
    sublanes the new vehicle covers; columns sharing a sublane starve each other.
    """
    used: list[tuple[int, int]] = []
    for c in sorted(offsets):
        left = c - vehicle_width / 2 + road_width / 2
        lo = math.floor(left / resolution + 1e-9)
        hi = math.ceil((left + vehicle_width) / resolution - 1e-9) - 1
        if used and lo <= used[-1][1]:
            raise ScenarioError(
                f"lateral_resolution = {resolution:g} is not allowed: with vehicles "
                f"{vehicle_width:g} m wide in columns at "
                f"{', '.join(f'{float(o):g}' for o in offsets)} m on a {road_width:g} m "
                "lane, neighbouring columns share a sublane; use a resolution such as 0.5 "
                "or 0.25 m")
        used.append((lo, hi))


def layout_route_text(params: ModelParameters, cfg: SumoConfig) -> str:
    """The route file on a user's network (``cfg.layout``; docs/networks.md, "What the run
    takes from the network"): empty when the user's route files carry the demand; mainline
    vehicles laterally at the lane's centre unless ``depart_pos_lat`` names a SUMO value."""
    lay = cfg.layout
    if lay is None or lay.route_files:
        return xml_file("routes", [])
    hv, av = vehicle_types(params, cfg)
    lines = [hv.to_xml(), av.to_xml(),
             f'<route id="{ROUTE_MAIN}" edges={quoteattr(" ".join(lay.main_route))}/>',
             f'<route id="{ROUTE_RAMP}" edges={quoteattr(" ".join(lay.ramp_route))}/>']
    lat = "center" if cfg.depart_pos_lat == "columns" else cfg.depart_pos_lat
    flows = [replace(f, depart_lane="free")
             for f in demand_flows(replace(cfg, depart_pos_lat=lat))]
    lines += [f.to_xml() for f in sorted(flows, key=lambda f: f.begin)]
    return xml_file("routes", lines)


def route_file_text(params: ModelParameters, cfg: SumoConfig,
                    initial: Sequence[InitialVehicle] = ()) -> str:
    """The route file: vTypes, the routes, initial vehicles, then the flows.

    Mainline flows start on ``approach`` when ``cfg.approach_length > 0`` (the network
    must have that edge), else on ``main`` at x = 0. On a user's network
    (``cfg.layout``): :func:`layout_route_text`.
    """
    if cfg.layout is not None:
        return layout_route_text(params, cfg)
    if cfg.depart_pos_lat == "columns":   # otherwise SUMO places every vehicle itself
        check_columns(params.road_width, params.vehicle_width, cfg.lateral_resolution,
                      insertion_columns(params.road_width, params.vehicle_width, 3))
    hv, av = vehicle_types(params, cfg)
    section = f"{MAIN} {MERGE} {DOWN}"
    lines = [hv.to_xml(), av.to_xml()]
    if cfg.approach_length > 0:
        approach = " ".join(approach_edges(cfg.approach_length, cfg.approach_piece))
        lines += [f'<route id="{ROUTE_MAIN}" edges="{approach} {section}"/>',
                  f'<route id="{ROUTE_SECTION}" edges="{section}"/>']
    else:
        lines.append(f'<route id="{ROUTE_MAIN}" edges="{section}"/>')
    lines.append(f'<route id="{ROUTE_RAMP}" edges="{RAMP_UP} {RAMP_DN} {MERGE} {DOWN}"/>')
    init_route = ROUTE_SECTION if cfg.approach_length > 0 else ROUTE_MAIN
    lines += [v.to_xml(init_route) for v in initial]
    flows = demand_flows(cfg, params.road_width, params.vehicle_width)
    if cfg.approach_length > 0:
        # a queue may reach back to the insertion point on the approach: "desired" would
        # hold a vehicle until the road ahead is free at that speed, "max" enters it at
        # the highest safe speed behind the queue
        flows = [replace(f, depart_speed="max") if f.route == ROUTE_MAIN else f
                 for f in flows]
    # SUMO drops departures listed out of time order: sort the flows by their begin
    lines += [f.to_xml() for f in sorted(flows, key=lambda f: f.begin)]
    return xml_file("routes", lines)


def write_route_file(path: Path, params: ModelParameters, cfg: SumoConfig,
                     initial: Sequence[InitialVehicle] = ()) -> Path:
    """Write :func:`route_file_text` to ``path`` atomically and return the path."""
    with atomic_file(path) as tmp:
        tmp.write_text(route_file_text(params, cfg, initial), encoding="utf-8")
    return path


def sumocfg_text(net_file: str, route_file: str, cfg: SumoConfig,
                 additional: Sequence[str] = ()) -> str:
    """A ``.sumocfg`` a user can open in sumo-gui (same options as arzsumo's runs).

    File names are written as given (SUMO reads relative ones from the config file's
    directory); ``additional`` lists additional files (detectors, the meter's program).
    The run ends at ``cfg.horizon`` (s).
    """
    inputs = {"net-file": net_file, "route-files": route_file}
    if additional:
        inputs["additional-files"] = ",".join(additional)
    opts = {
        "input": inputs,
        "time": {"begin": "0", "end": f"{cfg.horizon:.6g}",
                 "step-length": f"{cfg.step_length:.6g}"},
        "processing": {**({"lateral-resolution": f"{cfg.lateral_resolution:.6g}"}
                          if cfg.layout is None or cfg.layout.sublane else {}),
                       "time-to-teleport": f"{cfg.time_to_teleport:.6g}",
                       "eager-insert": str(cfg.eager_insert).lower(),
                       **cfg.collision_options},
        "random_number": {"seed": str(cfg.seed)},
    }
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', "<configuration>"]
    for section, values in opts.items():
        lines.append(f"    <{section}>")
        lines += [f"        <{k} value={quoteattr(v)}/>" for k, v in values.items()]
        lines.append(f"    </{section}>")
    lines.append("</configuration>")
    return "\n".join(lines) + "\n"


def write_gui_files(out_dir: Path, params: ModelParameters, cfg: SumoConfig,
                    net_name: str, route_name: str, cfg_name: str) -> list[Path]:
    """Write a route file and a ``.sumocfg`` beside the network (for sumo-gui)."""
    route = write_route_file(out_dir / route_name, params, cfg)
    with atomic_file(out_dir / cfg_name) as tmp:
        tmp.write_text(sumocfg_text(net_name, route_name, cfg), encoding="utf-8")
    return [route, out_dir / cfg_name]
