"""The section and its detectors read with sumolib (arzsumo.sumo.geometry), their figure
(arzsumo.plots.network through arzsumo.outputs.network) and ``arzsumo network``: counts and
positions against the layout of network (a) and the shipped network."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import arzsumo
from arzsumo.outputs.network import network_figure
from arzsumo.plots import plt
from tests.sumo import user_nets


@pytest.fixture(scope="module")
def net_a(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("two_lane_fig")
    user_nets.two_lane(d)
    (d / "a.toml").write_text(user_nets.TWO_LANE_TOML, encoding="utf-8")
    return d / "a.toml"


def _lines(ax, prefix: str) -> dict[str, object]:
    return {ln.get_gid(): ln for ln in ax.lines if (ln.get_gid() or "").startswith(prefix)}


def test_geometry_of_network_a(net_a):
    road = arzsumo.road_geometry(net_a)
    # lanes: s1..s3 (2 each), mrg (3), out (2), the ramp onramp and ramp_link (1 each)
    assert road.lane_edges.count("mrg") == 3 and len(road.lane_shapes) == 13
    assert road.lane_roles.count("section") == 6 and road.lane_roles.count("ramp") == 2
    np.testing.assert_allclose(road.loop_x, [6.0, 500.0, 1000.0, 1499.9])
    np.testing.assert_allclose(road.cell_x, np.arange(0.0, 1501.0, 50.0))
    assert road.downstream_x == pytest.approx(1750.0) and len(road.downstream) == 2
    assert road.join_x == pytest.approx(1500.0) and road.light_x == pytest.approx(-120.0)
    # on the plan: the road runs along network x from s1's start; lanes 3.5 m apart
    x0 = road.lane_shapes[0][0][0]
    loops = road.loops.reshape(4, 2, 2)
    np.testing.assert_allclose(loops[:3, :, 0] - x0, [[6.0] * 2, [500.0] * 2, [1000.0] * 2])
    np.testing.assert_allclose(loops[:, 1, 1] - loops[:, 0, 1], 3.5)
    np.testing.assert_allclose(road.cells[:, 1, 1] - road.cells[:, 0, 1], 7.0)
    np.testing.assert_allclose(road.cells[:21, 0, 0] - x0, np.arange(0.0, 1001.0, 50.0))
    # the light is the end of the ramp edge, where the ramp link starts
    assert np.allclose(road.light, road.lane_shapes[road.lane_edges.index("ramp_link")][0])
    assert any("s2 at 0.0 m, 2 E1" in line for line in road.placements())


def test_figure_draws_every_lane_cell_and_detector(net_a):
    road = arzsumo.road_geometry(net_a)
    fig = network_figure(road)
    plan, along = fig.axes[:2]
    lanes = _lines(plan, "lane:")
    assert len(lanes) == 13 and {"lane:mrg:2", "lane:onramp:0", "lane:s3:1"} <= set(lanes)
    np.testing.assert_allclose(lanes["lane:s2:1"].get_xydata(),
                               road.lane_shapes[road.lane_edges.index("s2") + 1])
    cells = _lines(along, "cell:")
    assert len(cells) == 31
    np.testing.assert_allclose(sorted(ln.get_xdata()[0] for ln in cells.values()),
                               np.arange(0.0, 1501.0, 50.0))
    loops = _lines(along, "loops:x")["loops:x"]
    np.testing.assert_allclose(sorted(set(loops.get_xdata())), road.loop_x)
    assert len(loops.get_xdata()) == 8                           # 4 stations x 2 lanes
    np.testing.assert_allclose(_lines(plan, "loops")["loops"].get_xydata(), road.loops)
    assert _lines(along, "downstream:x")["downstream:x"].get_xdata() == pytest.approx(
        [1750.0, 1750.0])
    assert _lines(along, "light:x")["light:x"].get_xdata() == pytest.approx([1380.0])
    np.testing.assert_allclose(_lines(plan, "light")["light"].get_xydata()[0], road.light)
    edges = _lines(along, "edge:")
    assert {g: ln.get_xdata()[0] for g, ln in edges.items()} == pytest.approx(
        {"edge:s1": 0.0, "edge:s2": 500.0, "edge:s3": 1000.0, "edge:mrg": 1500.0,
         "edge:out": 1650.0})
    plt.close(fig)


def test_the_shipped_network_is_drawn_too():
    road = arzsumo.road_geometry("default")
    assert road.edges[:3] == ("main", "merge", "down") and road.lanes == 1
    assert road.cell_x.size == 21 and road.ramp_edge == "ramp_up"
    fig = arzsumo.network_figure(road)
    assert len(_lines(fig.axes[1], "cell:")) == 21
    plt.close(fig)


def test_network_command_prints_and_draws(net_a, tmp_path):
    out = tmp_path / "a.png"
    proc = subprocess.run([sys.executable, "-m", "arzsumo.cli", "network", str(net_a),
                           "--figure", str(out)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "loop station x =   1000.0 m: s3 at 0.0 m, 2 E1" in proc.stdout
    assert "meter rm1 at the end of onramp" in proc.stdout
    assert out.read_bytes()[:4] == b"\x89PNG"
    bad = net_a.with_name("bad_fig.toml")
    bad.write_text(net_a.read_text(encoding="utf-8").replace('"s2"', '"s22"'), "utf-8")
    proc = subprocess.run([sys.executable, "-m", "arzsumo.cli", "network", str(bad),
                           "--figure", str(tmp_path / "b.png")], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1
    assert "section_edges" in proc.stderr and not (tmp_path / "b.png").exists()
