"""The kept configuration of a run keeps every file it read under a name of its own, even
when two of them share a name in different directories."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.run_files import RunFiles, _unique


def test_a_taken_name_gets_the_first_free_prefix():
    assert _unique("d.rou.xml", set()) == "d.rou.xml"
    assert _unique("d.rou.xml", {"d.rou.xml"}) == "2_d.rou.xml"
    assert _unique("d.rou.xml", {"d.rou.xml", "2_d.rou.xml"}) == "3_d.rou.xml"


def test_files_of_one_name_from_two_directories_are_both_kept(tmp_path):
    for d in "abc":
        (tmp_path / d).mkdir()
    net = tmp_path / "a" / "x.net.xml"
    route = tmp_path / "b" / "same.xml"
    extra = tmp_path / "c" / "same.xml"
    net.write_text("<net/>")
    route.write_text("<routes>b</routes>")
    extra.write_text("<additional>c</additional>")
    files = RunFiles(under=tmp_path)
    config = files.keep_config(net, route, [extra], SumoConfig())
    kept = {p.name: p.read_text() for p in (config.parent / "sumo").iterdir()}
    assert kept["same.xml"] == "<routes>b</routes>"
    assert kept["2_same.xml"] == "<additional>c</additional>"
    inputs = {e.tag: e.get("value") for e in ET.parse(config).getroot().find("input")}
    assert inputs["route-files"] == "sumo/same.xml"
    assert "sumo/2_same.xml" in inputs["additional-files"].split(",")
    files.remove()
