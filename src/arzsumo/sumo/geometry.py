"""The road of a run and the detectors placed on it, read from the network with sumolib.

:func:`road_geometry` turns a :class:`~arzsumo.sumo.layout.RoadLayout` and the run's
detector settings into a :class:`RoadGeometry`: the lane shapes of the section, of the
mainline past it and of the ramp, and where the loop stations, ALINEA's loop, the meter's
light and the cells' boundaries sit, on the plan (the network's x/y, m) and along the
section (x, m), as the run places them. :func:`shipped_layout` gives the shipped network
a layout too, so a scenario without ``[network]`` is drawn the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.errors import ScenarioError, require
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.layout import RoadLayout
from arzsumo.sumo.loops import BOUNDARY_GAP, placed_positions
from arzsumo.sumo.run_network import network_file
from arzsumo.sumo.user_network import NetworkRequest, read_layout

#: roles of the lane shapes, in drawing order
ROLES = ("mainline", "ramp", "section")


@dataclass(frozen=True)
class RoadGeometry:
    """A run's road and detectors, on the plan (network x/y, m) and along the section (m).

    Attributes
    ----------
    lane_edges, lane_roles : tuple of str
        The edge of each lane shape and its role: ``"section"``, ``"mainline"`` (the
        route past the section) or ``"ramp"`` (the ramp's edges up to the mainline).
    lane_shapes : tuple of numpy.ndarray
        Each lane's centre line, (n, 2) network x/y, m.
    light : numpy.ndarray
        (2,) the meter's stop line: the end of the ramp edge's lanes, m.
    loops, downstream : numpy.ndarray
        (stations * lanes, 2) the section's E1 loops and (outlet lanes, 2) ALINEA's, m.
    loop_x : numpy.ndarray
        The stations along the section (placed: x = 0 at the inlet gap, L at L - 0.1 m).
    downstream_x : float
        ALINEA's loop along the mainline route, m from x = 0.
    cell_x : numpy.ndarray
        The cells' boundaries 0, dx, ..., L, m.
    cells : numpy.ndarray
        (cells + 1, 2, 2) each boundary as a segment across the section's lanes, m.
    edges : tuple of str
        The mainline route's edges; ``edge_starts`` and ``edge_lengths`` (m) along x.
    length, width : float
        The section's L and W, m; ``lanes`` its lanes.
    join_x : float
        Where the ramp's route meets the mainline (the start of that edge), m.
    light_x : float
        The meter's stop line as the ramp's distance before ``join_x``, m (negative).
    ramp_length : float
        The ramp edge's length, m.
    meter_tl, ramp_edge : str
        The light and the ramp edge it holds.
    """

    lane_edges: tuple[str, ...]
    lane_roles: tuple[str, ...]
    lane_shapes: tuple[np.ndarray, ...]
    light: np.ndarray
    loops: np.ndarray
    downstream: np.ndarray
    loop_x: np.ndarray
    downstream_x: float
    cell_x: np.ndarray
    cells: np.ndarray
    edges: tuple[str, ...]
    edge_starts: tuple[float, ...]
    edge_lengths: tuple[float, ...]
    length: float
    width: float
    lanes: int
    join_x: float
    light_x: float
    ramp_length: float
    meter_tl: str = ""
    ramp_edge: str = ""

    def __post_init__(self) -> None:
        n = len(self.lane_shapes)
        require(n >= 1 and len(self.lane_edges) == n and len(self.lane_roles) == n,
                "lane_shapes", n, "one edge and one role per lane shape", ScenarioError)
        require(set(self.lane_roles) <= set(ROLES), "lane_roles", sorted(set(self.lane_roles)),
                f"roles among {list(ROLES)}", ScenarioError)

    def placements(self) -> list[str]:
        """The detectors in words, one line each (``arzsumo network`` prints them)."""
        sections = sum(1 for s in self.edge_starts if s < self.length - 1e-9)
        out = [f"section {', '.join(self.edges[:sections])}: L = {self.length:g} m, "
               f"{self.lanes} lane(s), W = {self.width:g} m, {self.cell_x.size - 1} cells of "
               f"{self.cell_x[1] - self.cell_x[0]:g} m"]
        for x in self.loop_x:
            edge, pos = self.locate(float(x))
            out.append(f"loop station x = {x:8.1f} m: {edge} at {pos:.1f} m, "
                       f"{self.lanes} E1 (one per lane)")
        edge, pos = self.locate(self.downstream_x)
        out.append(f"ALINEA loop    x = {self.downstream_x:8.1f} m: {edge} at {pos:.1f} m, "
                   f"{len(self.downstream)} E1")
        out.append(f"meter {self.meter_tl} at the end of {self.ramp_edge}, "
                   f"{-self.light_x:.1f} m before the ramp joins at x = {self.join_x:g} m")
        return out

    def locate(self, x: float) -> tuple[str, float]:
        """(edge, position on it, m) of x along the mainline route."""
        for edge, start, length in zip(self.edges, self.edge_starts, self.edge_lengths,
                                       strict=True):
            if x < start + length:
                return edge, max(x - start, 0.0)
        return self.edges[-1], self.edge_lengths[-1]


def shipped_layout(cfg: SumoConfig, workdir: Path) -> RoadLayout:
    """The run's layout: ``cfg.layout`` on a user's network; on the shipped one (built in
    ``workdir`` when the scenario changes its geometry) the section ``main``, the light
    ``meter`` and the ramp ``ramp_up``."""
    if cfg.layout is not None:
        return cfg.layout
    net = network_file(cfg, None, workdir)
    req = NetworkRequest(net_file=str(net), section_edges=("main",), meter_tls="meter",
                         ramp_edge="ramp_up")
    return read_layout(req, f"shipped network {net.name}")


def _at(lane: Any, pos: float) -> np.ndarray:
    """Plan point of ``pos`` m along ``lane`` (SUMO's lengths scaled to the shape's)."""
    from sumolib import geomhelper

    shape = lane.getShape()
    scale = geomhelper.polyLength(shape) / max(lane.getLength(), 1e-9)
    return np.array(geomhelper.positionAtShapeOffset(shape, pos * scale), float)


def _lanes_of(net: Any, layout: RoadLayout,
              ramp: tuple[str, ...]) -> tuple[list[str], list[str], list[np.ndarray]]:
    edges, roles, shapes = [], [], []
    for k, e in enumerate((*layout.main_route, *ramp)):
        role = "section" if k < layout.sections else \
            "mainline" if k < len(layout.main_route) else "ramp"
        for lane in net.getEdge(e).getLanes():
            edges.append(e)
            roles.append(role)
            shapes.append(np.asarray(lane.getShape(), float)[:, :2])
    return edges, roles, shapes


def _stations(net: Any, layout: RoadLayout, xs: Sequence[float]) -> np.ndarray:
    """Plan points of one E1 per lane at each x (as :func:`~arzsumo.sumo.loops.write_loops`
    places them)."""
    pts = []
    for x in xs:
        edge, pos = layout.locate(float(x))
        pts += [_at(lane, pos) for lane in net.getEdge(edge).getLanes()[:layout.lanes]]
    return np.array(pts, float).reshape(-1, 2)


def _normal(lane: Any, pos: float) -> np.ndarray:
    """Unit normal (to the left of the driving direction) of ``lane`` at ``pos`` m."""
    a = _at(lane, max(pos - 0.5, 0.0))
    b = _at(lane, min(pos + 0.5, lane.getLength()))
    d = b - a
    return np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-9)


def _boundaries(net: Any, layout: RoadLayout, cell_x: np.ndarray) -> np.ndarray:
    """Each cell boundary as a segment across the section, from the outer edge of lane 0
    (rightmost) to that of the last lane."""
    out = []
    for x in cell_x:
        edge, pos = layout.locate(min(float(x), layout.length - BOUNDARY_GAP))
        lanes = net.getEdge(edge).getLanes()
        first, last = lanes[0], lanes[layout.lanes - 1]
        a = _at(first, pos) - _normal(first, pos) * layout.lane_widths[0] / 2
        b = _at(last, pos) + _normal(last, pos) * layout.lane_widths[-1] / 2
        out.append([a, b])
    return np.array(out, float).reshape(-1, 2, 2)


def road_geometry(layout: RoadLayout, loop_x: Sequence[float], cell_length: float,
                  downstream_distance: float) -> RoadGeometry:
    """The road and detectors of a run on ``layout`` (read with sumolib;
    :func:`shipped_layout` for the shipped network): the loop stations asked for at
    ``loop_x`` (``[sensing]``, m) placed as the run places them, cells of ``cell_length``
    (m) and ALINEA's loop ``downstream_distance`` (m, ``[alinea] loop_distance_m``) past
    the start of the outlet edge."""
    import sumolib

    net = sumolib.net.readNet(str(layout.net_file))
    placed = placed_positions(loop_x, layout.length) if len(loop_x) else np.zeros(0)
    n = round(layout.length / cell_length)
    cell_x = np.linspace(0.0, layout.length, n + 1)
    k = layout.main_route.index(layout.outlet_edge)
    pos = min(downstream_distance, layout.outlet_length - BOUNDARY_GAP)
    outlet = net.getEdge(layout.outlet_edge).getLanes()
    join = next(e for e in layout.ramp_route if e in layout.main_route)
    ramp = layout.ramp_route[:layout.ramp_route.index(join)]
    ramp_lanes = net.getEdge(layout.ramp_edge).getLanes()
    edges, roles, shapes = _lanes_of(net, layout, ramp)
    return RoadGeometry(
        lane_edges=tuple(edges), lane_roles=tuple(roles), lane_shapes=tuple(shapes),
        light=np.mean([np.asarray(ln.getShape()[-1][:2], float) for ln in ramp_lanes], 0),
        loops=_stations(net, layout, placed),
        downstream=np.array([_at(ln, pos) for ln in outlet], float).reshape(-1, 2),
        loop_x=np.asarray(placed, float), downstream_x=layout.starts[k] + pos,
        cell_x=cell_x, cells=_boundaries(net, layout, cell_x), edges=layout.main_route,
        edge_starts=layout.starts, edge_lengths=layout.lengths, length=layout.length,
        width=layout.width, lanes=layout.lanes,
        join_x=layout.starts[layout.main_route.index(join)],
        light_x=-float(sum(net.getEdge(e).getLength() for e in ramp[1:])),
        ramp_length=float(net.getEdge(layout.ramp_edge).getLength()),
        meter_tl=layout.meter_tl, ramp_edge=layout.ramp_edge)
