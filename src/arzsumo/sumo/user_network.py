"""A user's SUMO network read and checked with sumolib before SUMO starts (``[network]``).

:class:`NetworkRequest` is the ``[network]`` table as the user wrote it (file names
relative to the scenario file); :func:`read_layout` checks it against the network and
returns the :class:`~arzsumo.sumo.layout.RoadLayout` the run uses. Each refusal is one
:class:`~arzsumo.errors.ScenarioError` naming the key and the value as written; the
checks and their messages are listed in docs/networks.md, "Checked before SUMO starts".
"""

from __future__ import annotations

import difflib
import itertools
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arzsumo.errors import ScenarioError, require
from arzsumo.sumo.layout import RoadLayout
from arzsumo.sumo.vtypes import AV_TYPE
from arzsumo.tables import not_allowed

#: the mainline route past the section is followed this far at most (edges)
ROUTE_EDGES = 50
#: the ramp must join the mainline within this many edges past the section's end
JOIN_WITHIN = 2
#: lane widths along the section may differ by this much, m
WIDTH_TOLERANCE = 0.01


@dataclass(frozen=True)
class NetworkRequest:
    """The ``[network]`` table (SI), as written: names, offsets, files relative to ``base``.

    The fields are the table's keys (docs/scenarios.md, "[network]"); ``base`` is the
    directory the file names are relative to (the scenario file's).
    """

    net_file: str
    section_edges: tuple[str, ...]
    meter_tls: str
    ramp_edge: str
    route_files: tuple[str, ...] = ()
    av_types: tuple[str, ...] = ()
    start_offset: float = 0.0
    end_offset: float = 0.0
    sublane: bool = True
    base: str = "."

    def absolute_table(self, table: Mapping[str, Any]) -> dict[str, Any]:
        """``table`` (this ``[network]`` as written) with its files as absolute paths: a
        scenario written elsewhere (``arzsumo identify``, ``arzsumo calibrate``) still
        finds the network."""
        out = {**table, "net_file": str(self.path(self.net_file).resolve())}
        if self.route_files:
            out["route_files"] = [str(self.path(r).resolve()) for r in self.route_files]
        return out

    def __post_init__(self) -> None:
        for name in ("start_offset", "end_offset"):
            v = getattr(self, name)
            require(isinstance(v, int | float) and 0.0 <= v < 1e7, name, v,
                    "a distance >= 0 m", ScenarioError)
        require(len(set(self.section_edges)) == len(self.section_edges), "section_edges",
                list(self.section_edges), "distinct edge ids", ScenarioError)
        require(not self.av_types or bool(self.route_files), "av_types", list(self.av_types),
                "only with route_files (without them the run writes its own vTypes)",
                ScenarioError)

    def path(self, name: str) -> Path:
        """``name`` made absolute against :attr:`base`."""
        p = Path(name)
        return p if p.is_absolute() else Path(self.base) / p


def _read_net(req: NetworkRequest, at: str) -> Any:
    import sumolib

    path = req.path(req.net_file)
    if not path.is_file():
        raise not_allowed(at, "net_file", req.net_file,
                          f"an existing SUMO network file ({str(path)!r} is missing)")
    try:
        return sumolib.net.readNet(str(path), withInternal=True)
    except Exception as exc:  # sumolib raises whatever its XML parser raises
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise not_allowed(at, "net_file", req.net_file,
                          f"a SUMO network sumolib can read ({text})") from None


def _route_types(req: NetworkRequest, at: str) -> set[str]:
    """The vType (and vType distribution) ids of the route files; each file must parse."""
    types: set[str] = set()
    for name in req.route_files:
        path = req.path(name)
        if not path.is_file():
            raise not_allowed(at, "route_files", list(req.route_files),
                              f"existing route files ({str(path)!r} is missing)")
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as exc:
            raise not_allowed(at, "route_files", list(req.route_files),
                              f"route files that parse ({name}: {exc})") from None
        types |= {e.get("id", "") for e in root.iter()
                  if e.tag in ("vType", "vTypeDistribution")}
    return types


def _edge(net: Any, edge_id: str, key: str, value: Any, at: str) -> Any:
    if net.hasEdge(edge_id) and not edge_id.startswith(":"):
        return net.getEdge(edge_id)
    ids = [e.getID() for e in net.getEdges()]
    near = difflib.get_close_matches(edge_id, ids, n=1)
    hint = f"; did you mean {near[0]!r}?" if near else ""
    raise not_allowed(at, key, value, f"edges of the network (edge {edge_id!r} is not in "
                                      f"it{hint})")


def _section(net: Any, req: NetworkRequest, at: str) -> list[Any]:
    """The section's edges: existing, connected in order, with the same lanes."""
    value = list(req.section_edges)
    require(len(value) >= 1, "section_edges", value, "at least one edge", ScenarioError)
    edges = [_edge(net, e, "section_edges", value, at) for e in req.section_edges]
    for a, b in itertools.pairwise(edges):
        if b not in a.getOutgoing():
            raise not_allowed(at, "section_edges", value,
                              f"edges in driving order ({a.getID()!r} does not lead into "
                              f"{b.getID()!r})")
    widths = [lane.getWidth() for lane in edges[0].getLanes()]
    for e in edges[1:]:
        w = [lane.getWidth() for lane in e.getLanes()]
        if len(w) != len(widths) or any(abs(p - q) > WIDTH_TOLERANCE
                                        for p, q in zip(w, widths, strict=True)):
            raise not_allowed(at, "section_edges", value,
                              f"a section with the same lanes along its length "
                              f"({edges[0].getID()!r} has {len(widths)} lane(s) "
                              f"{_widths(widths)}, {e.getID()!r} {len(w)} {_widths(w)}); "
                              "end the section where the lanes change")
    return edges


def _widths(w: list[float]) -> str:
    return "(" + ", ".join(f"{x:g}" for x in w) + " m)"


def _onward(edges: list[Any]) -> list[Any]:
    """The section's edges followed downstream to a sink: at each fork the outgoing edge
    with the most lanes, then the highest priority (a freeway's through road)."""
    route = list(edges)
    while len(route) < len(edges) + ROUTE_EDGES:
        nxt = [e for e in route[-1].getOutgoing() if e not in route]
        if not nxt:
            break
        route.append(max(nxt, key=lambda e: (e.getLaneNumber(), e.getPriority())))
    return route


def _ramp_route(net: Any, req: NetworkRequest, route: list[Any], sections: int,
                at: str) -> list[Any]:
    """The ramp's edges up to where it joins the mainline route, then the route onwards."""
    ramp = _edge(net, req.ramp_edge, "ramp_edge", req.ramp_edge, at)
    index = {e: k for k, e in enumerate(route)}
    paths, seen = [[ramp]], {ramp}
    while paths:
        path = paths.pop(0)
        for e in path[-1].getOutgoing():
            if e in index:
                k = index[e]
                if k < sections:
                    raise not_allowed(at, "ramp_edge", req.ramp_edge,
                                      f"a ramp joining the mainline past the section (it "
                                      f"joins section edge {e.getID()!r}, inside [0, L])")
                if k >= sections + JOIN_WITHIN:
                    raise not_allowed(at, "ramp_edge", req.ramp_edge,
                                      f"a ramp joining the mainline just past the section "
                                      f"(it joins {e.getID()!r}, {k - sections + 1} edges "
                                      "past its end)")
                return path + route[k:]
            if e not in seen and len(path) < ROUTE_EDGES:
                seen.add(e)
                paths.append([*path, e])
    raise not_allowed(at, "ramp_edge", req.ramp_edge,
                      "a ramp edge that leads to the mainline past the section (no path "
                      "from it reaches the section's outlet)")


def _meter(net: Any, req: NetworkRequest, at: str) -> tuple[int, tuple[int, ...]]:
    """The light's number of links and the indices of those leaving the ramp edge."""
    lights = {t.getID(): t for t in net.getTrafficLights()}
    tls = lights.get(req.meter_tls)
    if tls is None:
        near = difflib.get_close_matches(req.meter_tls, list(lights), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise not_allowed(at, "meter_tls", req.meter_tls,
                          f"a traffic light of the network ({len(lights)} there{hint})")
    conns = tls.getConnections()
    links = max((c[2] for c in conns), default=-1) + 1
    ramp = tuple(sorted({c[2] for c in conns if c[0].getEdge().getID() == req.ramp_edge}))
    if not ramp:
        raise not_allowed(at, "meter_tls", req.meter_tls,
                          f"a light controlling a link out of ramp_edge = {req.ramp_edge!r} "
                          "(it controls none)")
    return links, ramp


def _short(v: float) -> float | int:
    """A distance as a file would write it: 800 for 800.0."""
    return int(v) if float(v).is_integer() else v


def _offsets(req: NetworkRequest, edges: list[Any], at: str) -> None:
    first, last = edges[0].getLength(), edges[-1].getLength()
    if req.start_offset >= first:
        raise not_allowed(at, "start_offset_m", _short(req.start_offset),
                          f"a distance below the first section edge's length {first:g} m")
    if req.end_offset >= last:
        raise not_allowed(at, "end_offset_m", _short(req.end_offset),
                          f"a distance below the last section edge's length {last:g} m")
    if len(edges) == 1 and req.start_offset + req.end_offset >= first:
        raise not_allowed(at, "end_offset_m", _short(req.end_offset),
                          f"offsets leaving a section: start_offset_m + end_offset_m below "
                          f"the edge's length {first:g} m")


def read_layout(req: NetworkRequest, at: str) -> RoadLayout:
    """Check ``req`` against its network with sumolib; the run's :class:`RoadLayout`.

    ``at`` prefixes every message (``scenario.toml: [network]``).
    """
    net = _read_net(req, at)
    types = _route_types(req, at)
    for t in req.av_types:
        if t not in types:
            raise not_allowed(at, "av_types", list(req.av_types),
                              f"vType ids of the route files ({t!r} is not among "
                              f"{sorted(types)})")
    edges = _section(net, req, at)
    _offsets(req, edges, at)
    route = _onward(edges)
    ramp = _ramp_route(net, req, route, len(edges), at)
    links, ramp_links = _meter(net, req, at)
    lengths = [float(e.getLength()) for e in route]
    starts = itertools.accumulate(lengths[:-1], initial=-req.start_offset)
    section = sum(lengths[:len(edges)]) - req.start_offset - req.end_offset
    internal = tuple(tuple(sorted({c.getViaLaneID().rsplit("_", 1)[0]
                                   for c in a.getConnections(b) if c.getViaLaneID()}))
                     for a, b in itertools.pairwise(edges))
    ramp_edge = ramp[0]
    join = route.index(next(e for e in ramp if e in route))   # where the ramp joins
    outlet = route[min(join + 1, len(route) - 1)]
    return RoadLayout(
        net_file=req.path(req.net_file).resolve(),
        route_files=tuple(req.path(r).resolve() for r in req.route_files),
        main_route=tuple(e.getID() for e in route), starts=tuple(starts),
        lengths=tuple(lengths), sections=len(edges), length=float(section),
        lane_widths=tuple(float(lane.getWidth()) for lane in edges[0].getLanes()),
        internal=internal, meter_tl=req.meter_tls, meter_links=links,
        ramp_links=ramp_links, ramp_edge=req.ramp_edge,
        ramp_route=tuple(e.getID() for e in ramp),
        ramp_length=float(ramp_edge.getLength()) * ramp_edge.getLaneNumber(),
        outlet_edge=outlet.getID(), outlet_length=float(outlet.getLength()),
        outlet_lanes=outlet.getLaneNumber(),
        av_types=frozenset(req.av_types) if req.route_files else frozenset({AV_TYPE}),
        sublane=req.sublane,
        ramp_free_time=float(ramp_edge.getLength()) / max(float(ramp_edge.getSpeed()), 0.1))
