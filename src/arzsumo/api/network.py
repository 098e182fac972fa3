"""The road a scenario runs on, and the detectors placed on it: :func:`road_geometry`
(the numbers) and :func:`network_figure` (their figure). ``arzsumo network`` calls them.

Both check the scenario's ``[network]`` table as :func:`arzsumo.prepare` does (sumolib,
before SUMO starts); a scenario without one is drawn on the shipped network.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from arzsumo.api.scenarios import load_scenario
from arzsumo.bridge.road import with_network
from arzsumo.scenario import Scenario
from arzsumo.sumo.geometry import RoadGeometry, shipped_layout
from arzsumo.sumo.geometry import road_geometry as _geometry

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["network_figure", "road_geometry"]


def road_geometry(scenario: str | Path | Scenario | None = None) -> RoadGeometry:
    """The section, the ramp, the meter's light and the detectors of a scenario's run.

    Parameters
    ----------
    scenario : str, Path or Scenario, optional
        A scenario file, a shipped name or a loaded scenario (default: the shipped one).

    Returns
    -------
    RoadGeometry
        Lane shapes (network x/y, m), the loop stations, ALINEA's loop, the light and the
        cells' boundaries, on the plan and along x (m); ``placements()`` in words.

    Examples
    --------
    >>> import arzsumo
    >>> road = arzsumo.road_geometry("default")
    >>> road.length, road.lanes, road.cell_x.size - 1            # m, lanes, cells
    (1000.0, 1, 20)
    """
    sc = with_network(load_scenario(scenario))
    with tempfile.TemporaryDirectory(prefix="arzsumo-net-") as tmp:
        layout = shipped_layout(sc.sumo, Path(tmp))
        return _geometry(layout, sc.sensing.loop_x(sc.params.length), sc.sumo.cell_length,
                         sc.alinea.loop_distance)


def network_figure(scenario: str | Path | Scenario | RoadGeometry | None = None) -> Figure:
    """The figure of a scenario's section and its detectors (nothing written).

    Parameters
    ----------
    scenario : str, Path, Scenario or RoadGeometry, optional
        As :func:`road_geometry`, or its result.

    Returns
    -------
    matplotlib.figure.Figure
        The plan (to scale) and the section along x: edges, ramp, the meter's light, the
        loop stations (one E1 per lane), ALINEA's loop and the cells' boundaries.
    """
    from arzsumo.outputs.network import network_figure as draw

    return draw(scenario if isinstance(scenario, RoadGeometry) else road_geometry(scenario))
