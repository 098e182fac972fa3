"""The ``[network]`` section: the laws on a SUMO network the user brings.

Here the table is read for its shape only; :func:`arzsumo.bridge.session.prepare_run`
checks it against the network with sumolib before SUMO starts
(:func:`arzsumo.sumo.user_network.read_layout`). Without the table a run uses the shipped
network. Keys: docs/scenarios.md; docs/networks.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from arzsumo.errors import ScenarioError
from arzsumo.sumo.user_network import NetworkRequest
from arzsumo.tables import Key, read_section

#: [network] key -> NetworkRequest field (SI)
NETWORK_KEYS: dict[str, Key] = {
    "net_file": Key("net_file", "string",
                    doc="the SUMO network (.net.xml), relative to the scenario file"),
    "route_files": Key("route_files", "strings",
                       doc="the user's route files (demand and vTypes), relative to the "
                           "scenario file; without them the [sumo] demand keys make flows "
                           "on the named edges"),
    "section_edges": Key("section_edges", "strings",
                         doc="the section's edges from x = 0 to x = L, in driving order "
                             "(the same lanes along them)"),
    "meter_tls": Key("meter_tls", "string",
                     doc="the traffic light that meters the on-ramp"),
    "ramp_edge": Key("ramp_edge", "string",
                     doc="the ramp edge the meter holds (its queue storage); it joins the "
                         "mainline just past the section"),
    "av_types": Key("av_types", "strings",
                    doc="vType ids of the route files counted as AVs; every other vType "
                        "is an HV (only with route_files)"),
    "start_offset_m": Key("start_offset", unit="m",
                          doc="the section starts this far along its first edge"),
    "end_offset_m": Key("end_offset", unit="m",
                        doc="the section ends this far before its last edge's end"),
    "sublane": Key("sublane", "bool",
                   doc="run SUMO's sublane model with [sumo] lateral_resolution_m (false: "
                       "lane changes only)"),
}
#: keys a [network] table must have
REQUIRED = ("net_file", "section_edges", "meter_tls", "ramp_edge")


def network_section(table: Mapping[str, Any], at: str, source: str) -> NetworkRequest | None:
    """The NetworkRequest of a ``[network]`` table (keys already checked), None without
    one; file names are relative to the directory of ``source``."""
    if not table:
        return None
    missing = [k for k in REQUIRED if k not in table]
    if missing:
        raise ScenarioError(f"{at} needs the keys {', '.join(REQUIRED)}; missing: "
                            f"{', '.join(missing)}")
    base = Path(source).parent if Path(source).is_file() else Path(".")
    return read_section(NetworkRequest, table, NETWORK_KEYS, at, base=str(base.resolve()))
