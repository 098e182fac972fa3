"""Two networks the package does not ship, built by netconvert from plain XML.

(a) ``two_lane``: two 3.5 m lanes, a 1.5 km section over the edges ``s1``, ``s2``,
``s3``; the ramp ``onramp`` held by the light ``rm1`` joins the acceleration lane of
``mrg``; the vTypes ``car`` (HV) and ``cav`` (AV) and the demand in ``demand.rou.xml``.
(b) ``partway``: one 3.5 m lane; the section starts 300 m along ``up`` (800 m) and ends
at the end of ``sec`` (500 m): L = 1000 m; the ramp ``rin`` held by ``gate``; no route
file (the [sumo] demand keys make the flows).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from arzsumo.sumo.paths import sumo_binary


def _write(path: Path, root: str, lines: list[str]) -> None:
    body = "\n".join(f"    {ln}" for ln in lines)
    path.write_text(f'<?xml version="1.0" encoding="UTF-8"?>\n<{root}>\n{body}\n</{root}>\n',
                    encoding="utf-8")


def _netconvert(d: Path, name: str) -> Path:
    out = d / f"{name}.net.xml"
    subprocess.run([str(sumo_binary("netconvert")), "--node-files", f"{name}.nod.xml",
                    "--edge-files", f"{name}.edg.xml", "--connection-files", f"{name}.con.xml",
                    "--tllogic-files", f"{name}.tll.xml", "--no-turnarounds", "true",
                    "--output-file", out.name, "--no-warnings", "true"],
                   cwd=d, check=True, capture_output=True)
    return out


def _ramp(name: str, tl: str, ramp: str, link: str, join: str, x: float,
          acc_lanes: int) -> tuple[list[str], list[str], list[str], list[str]]:
    nodes = [f'<node id="M" x="{x - 72}" y="-96" type="traffic_light" tl="{tl}"/>',
             f'<node id="R" x="{x - 252}" y="-336"/>']
    edges = [f'<edge id="{ramp}" from="R" to="M" numLanes="1" speed="13.89" priority="1" '
             'length="300" width="3.5"/>',
             f'<edge id="{link}" from="M" to="J" numLanes="1" speed="13.89" priority="1" '
             'length="120" width="3.5"/>']
    cons = [f'<connection from="{ramp}" to="{link}" fromLane="0" toLane="0"/>',
            f'<connection from="{link}" to="{join}" fromLane="0" toLane="0"/>']
    tll = [f'<tlLogic id="{tl}" type="static" programID="0" offset="0">',
           '    <phase duration="3" state="G"/>', '    <phase duration="1" state="y"/>',
           '    <phase duration="2" state="r"/>', "</tlLogic>",
           f'<connection from="{ramp}" to="{link}" fromLane="0" toLane="0" tl="{tl}" '
           'linkIndex="0"/>']
    del name, acc_lanes
    return nodes, edges, cons, tll


def two_lane(d: Path) -> Path:
    """Network (a) and its route file in ``d``; returns the network file."""
    d.mkdir(parents=True, exist_ok=True)
    nodes = [f'<node id="N{k}" x="{500.0 * k}" y="0" type="priority"/>' for k in range(3)]
    nodes += ['<node id="J" x="1500" y="0" type="priority"/>',
              '<node id="K" x="1650" y="0" type="priority"/>',
              '<node id="Z" x="2150" y="0"/>']
    ends = ["N0", "N1", "N2", "J"]
    edges = [f'<edge id="s{k + 1}" from="{ends[k]}" to="{ends[k + 1]}" numLanes="2" '
             'speed="22.22" priority="3" length="500" width="3.5"/>' for k in range(3)]
    edges += ['<edge id="mrg" from="J" to="K" numLanes="3" speed="22.22" priority="3" '
              'length="150" width="3.5"/>',
              '<edge id="out" from="K" to="Z" numLanes="2" speed="16.67" priority="3" '
              'length="500" width="3.5"/>']
    cons = [f'<connection from="s{k}" to="s{k + 1}" fromLane="{i}" toLane="{i}"/>'
            for k in (1, 2) for i in (0, 1)]
    cons += [f'<connection from="s3" to="mrg" fromLane="{i}" toLane="{i + 1}"/>' for i in (0, 1)]
    cons += [f'<connection from="mrg" to="out" fromLane="{i + 1}" toLane="{i}"/>' for i in (0, 1)]
    n, e, c, t = _ramp("two_lane", "rm1", "onramp", "ramp_link", "mrg", 1500.0, 1)
    _write(d / "two_lane.nod.xml", "nodes", nodes + n)
    _write(d / "two_lane.edg.xml", "edges", edges + e)
    _write(d / "two_lane.con.xml", "connections", cons + c)
    _write(d / "two_lane.tll.xml", "tlLogics", t)
    _write(d / "demand.rou.xml", "routes", [
        '<vType id="car" length="5" minGap="2.5" maxSpeed="22.22" sigma="0.5" width="1.8"/>',
        '<vType id="cav" carFollowModel="ACC" length="5" minGap="8" maxSpeed="19.44" '
        'width="1.8"/>',
        '<route id="main" edges="s1 s2 s3 mrg out"/>',
        '<route id="ramp" edges="onramp ramp_link mrg out"/>',
        '<flow id="m_car" type="car" route="main" begin="0" end="3600" period="1.2" '
        'departLane="free" departSpeed="desired"/>',
        '<flow id="m_cav" type="cav" route="main" begin="0" end="3600" period="4" '
        'departLane="free" departSpeed="desired"/>',
        '<flow id="r_car" type="car" route="ramp" begin="0" end="3600" period="4" '
        'departLane="0" departSpeed="max"/>'])
    return _netconvert(d, "two_lane")


def partway(d: Path) -> Path:
    """Network (b) in ``d``; returns the network file."""
    d.mkdir(parents=True, exist_ok=True)
    nodes = ['<node id="A" x="0" y="0" type="priority"/>',
             '<node id="B" x="800" y="0" type="priority"/>',
             '<node id="J" x="1300" y="0" type="priority"/>',
             '<node id="K" x="1450" y="0" type="priority"/>',
             '<node id="Z" x="1950" y="0"/>']
    edges = ['<edge id="up" from="A" to="B" numLanes="1" speed="22.22" priority="3" '
             'length="800" width="3.5"/>',
             '<edge id="sec" from="B" to="J" numLanes="1" speed="22.22" priority="3" '
             'length="500" width="3.5"/>',
             '<edge id="acc" from="J" to="K" numLanes="2" speed="22.22" priority="3" '
             'length="150" width="3.5"/>',
             '<edge id="tail" from="K" to="Z" numLanes="1" speed="13.89" priority="3" '
             'length="500" width="3.5"/>']
    cons = ['<connection from="up" to="sec" fromLane="0" toLane="0"/>',
            '<connection from="sec" to="acc" fromLane="0" toLane="1"/>',
            '<connection from="acc" to="tail" fromLane="1" toLane="0"/>']
    n, e, c, t = _ramp("partway", "gate", "rin", "rlink", "acc", 1300.0, 1)
    _write(d / "partway.nod.xml", "nodes", nodes + n)
    _write(d / "partway.edg.xml", "edges", edges + e)
    _write(d / "partway.con.xml", "connections", cons + c)
    _write(d / "partway.tll.xml", "tlLogics", t)
    return _netconvert(d, "partway")


TWO_LANE_TOML = """\
name = "two_lane"
[network]
net_file = "two_lane.net.xml"
route_files = ["demand.rou.xml"]
section_edges = ["s1", "s2", "s3"]
meter_tls = "rm1"
ramp_edge = "onramp"
av_types = ["cav"]
[sumo]
horizon_s = 40
[run]
warmup_s = 40
[sensing]
kinds = ["probe", "loops"]
loop_spacing_m = 500
"""

PARTWAY_TOML = """\
name = "partway"
[network]
net_file = "partway.net.xml"
section_edges = ["up", "sec"]
start_offset_m = 300
meter_tls = "gate"
ramp_edge = "rin"
sublane = false
[sumo]
horizon_s = 40
demand_h_veh_h = 1500
demand_a_veh_h = 300
ramp_demand_veh_h = 600
[run]
warmup_s = 40
[sensing]
kinds = ["probe", "loops"]
loop_spacing_m = 250
"""
