"""The road a run measures and meters: which edges are the section, which light the meter.

Without a ``[network]`` table no :class:`RoadLayout` exists and every module keeps the
shipped network's fixed IDs (:mod:`arzsumo.sumo.network`: the section ``main``, the light
``meter``); with one, :func:`arzsumo.sumo.user_network.read_layout` returns the layout the
run carries on :attr:`arzsumo.sumo.config.SumoConfig.layout`. x is the distance from the
section's start (``start_offset`` metres along the first section edge) to the vehicle's
front, over the section's edges in order to x = L and on along ``main_route`` past it, so
a detector "d metres past the section" is placed by :meth:`RoadLayout.locate`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from arzsumo.errors import ScenarioError, require


@dataclass(frozen=True)
class RoadLayout:
    """The section, the meter and the vehicle classes of a user's network (SI: m).

    ``main_route`` holds the mainline's edges in driving order, from the first section edge
    to a sink, with each one's start x (``starts``; the first is ``-start_offset``) and
    ``lengths``; its first ``sections`` edges are the section, of length L (``length``)
    and the same lanes (``lane_widths``) on every edge. ``internal`` lists, per boundary
    between section edges, the internal edges a vehicle crosses there (counted at the next
    edge's start). Without ``route_files`` the ``[sumo]`` demand keys make flows on
    ``main_route`` and ``ramp_route``.

    The light ``meter_tl`` has ``meter_links`` signals (its state strings are this long);
    the meter switches those leading out of ``ramp_edge`` (``ramp_links``), every other
    link stays green. ``ramp_route`` runs from ``ramp_edge`` to the mainline, then along
    it to its sink; ``ramp_length`` is ``ramp_edge``'s length times its lanes (the queue
    storage) and ``ramp_free_time`` its length over its speed limit, s (what a ramp
    vehicle's wait at the meter is net of). ``outlet_edge`` (``outlet_length`` m,
    ``outlet_lanes`` lanes) carries ALINEA's loop: the edge past the one the ramp joins
    (that one if the route ends there). ``av_types`` are the vType IDs counted as AVs;
    ``sublane`` False runs lane changes only, no sublane model. docs/networks.md, "What
    the run takes from the network", says how a run uses each.
    """

    net_file: Path
    route_files: tuple[Path, ...]
    main_route: tuple[str, ...]
    starts: tuple[float, ...]
    lengths: tuple[float, ...]
    sections: int
    length: float
    lane_widths: tuple[float, ...]
    internal: tuple[tuple[str, ...], ...]
    meter_tl: str
    meter_links: int
    ramp_links: tuple[int, ...]
    ramp_edge: str
    ramp_route: tuple[str, ...]
    ramp_length: float
    outlet_edge: str
    outlet_length: float
    outlet_lanes: int
    av_types: frozenset[str]
    sublane: bool = True
    ramp_free_time: float = 0.0

    def __post_init__(self) -> None:
        n = len(self.main_route)
        require(n >= 1 and len(self.starts) == n and len(self.lengths) == n,
                "main_route", self.main_route, "edges with a start and a length each",
                ScenarioError)
        require(1 <= self.sections <= n, "sections", self.sections,
                f"1..{n} edges of the main route", ScenarioError)
        require(math.isfinite(self.length) and self.length > 0, "length", self.length,
                "a section length > 0 m", ScenarioError)
        require(len(self.lane_widths) >= 1 and min(self.lane_widths) > 0, "lane_widths",
                self.lane_widths, "at least one lane of width > 0 m", ScenarioError)
        require(self.meter_links >= 1 and len(self.ramp_links) >= 1
                and all(0 <= i < self.meter_links for i in self.ramp_links), "ramp_links",
                self.ramp_links, f"link indices in [0, {self.meter_links})", ScenarioError)

    @property
    def section_edges(self) -> tuple[str, ...]:
        """The section's edges, upstream first."""
        return self.main_route[:self.sections]

    @property
    def lanes(self) -> int:
        """Lanes of the section."""
        return len(self.lane_widths)

    @property
    def width(self) -> float:
        """The section's width (sum of its lane widths), m: the model's road width W."""
        return float(sum(self.lane_widths))

    def signal(self, state: str) -> str:
        """The light's state string with the ramp's links at ``state`` (one of SUMO's
        signal characters) and every other link green."""
        chars = ["G"] * self.meter_links
        for i in self.ramp_links:
            chars[i] = state
        return "".join(chars)

    def locate(self, x: float) -> tuple[str, float]:
        """(edge, position on it, m) of x along :attr:`main_route`; positions past the
        route's end are refused."""
        for edge, start, length in zip(self.main_route, self.starts, self.lengths,
                                       strict=True):
            if x < start + length:
                return edge, max(x - start, 0.0)
        raise ScenarioError(f"x = {x:g} m lies past the end of the mainline route "
                            f"({self.starts[-1] + self.lengths[-1]:g} m from x = 0)")

    def section_places(self) -> tuple[tuple[str, float], ...]:
        """(edge, x of its position 0) of every edge a section vehicle may be on: the
        section's edges and the internal edges between them (at the next edge's start)."""
        out = [(e, s) for e, s in zip(self.section_edges, self.starts, strict=False)]
        for k, ids in enumerate(self.internal):
            out += [(e, self.starts[k + 1]) for e in ids]
        return tuple(out)


class VehicleClasses:
    """Which vehicles are AVs and which came from the ramp, asked of SUMO once per id.

    Without a layout (the shipped network) the class is in the id: ``av...`` and
    ``ramp...`` (:mod:`arzsumo.sumo.demand`). With one, an AV is a vehicle whose vType is
    among ``av_types`` and a ramp vehicle one whose route holds the ramp edge.
    """

    def __init__(self, lib: ModuleType | None, layout: RoadLayout | None) -> None:
        self.lib, self.layout = lib, layout
        self._av: dict[str, bool] = {}
        self._ramp: dict[str, bool] = {}

    def av(self, vid: str) -> bool:
        """Whether ``vid`` is an AV."""
        if self.layout is None or self.lib is None:
            return vid.startswith("av")
        hit = self._av.get(vid)
        if hit is None:
            hit = self._av[vid] = self.lib.vehicle.getTypeID(vid) in self.layout.av_types
        return hit

    def ramp(self, vid: str) -> bool:
        """Whether ``vid`` entered from the ramp."""
        if self.layout is None or self.lib is None:
            return vid.startswith("ramp")
        hit = self._ramp.get(vid)
        if hit is None:
            hit = self._ramp[vid] = self.layout.ramp_edge in self.lib.vehicle.getRoute(vid)
        return hit

    def recorded(self, vid: str) -> bool:
        """Whether ``vid`` entered from the ramp, from what :meth:`ramp` learnt while SUMO
        ran (no SUMO call: usable once it has closed). The run asks :meth:`ramp` of every
        vehicle SUMO loads, so one never asked is a mainline vehicle."""
        if self.layout is None or self.lib is None:
            return vid.startswith("ramp")
        return self._ramp.get(vid, False)

    def av_mask(self, ids: Sequence[str]) -> np.ndarray:
        """Boolean array: which of ``ids`` are AVs."""
        return np.fromiter((self.av(v) for v in ids), bool, len(ids))
