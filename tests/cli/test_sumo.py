"""The SUMO commands of the CLI: build-net and a tiny calibrate smoke run."""

import json
import subprocess
import sys
import tomllib

import pytest

from arzsumo.cli import main
from arzsumo.sumo.calibration_io import load_green_share_curve
from arzsumo.sumo.network import NetworkSpec, build_network, edge_lengths
from arzsumo.sumo.paths import NET_FILE, SumoError, default_nets_dir, nets_dir


def test_shipped_network_has_an_exactly_1000_m_mainline():
    lengths = edge_lengths(nets_dir() / NET_FILE)
    assert lengths["main"] == 1000.0
    for name in ("ramp.nod.xml", "ramp.edg.xml", "ramp.con.xml", "ramp.tll.xml",
                 "ramp.rou.xml", "ramp.sumocfg"):
        assert (default_nets_dir() / name).is_file()


def test_build_net_writes_sources_and_network(tmp_path, capsys):
    assert main(["build-net", "--out", str(tmp_path)]) == 0
    assert "main 1000.00" in capsys.readouterr().out
    import sumolib

    net = sumolib.net.readNet(str(tmp_path / NET_FILE))
    main_edge = net.getEdge("main")
    assert main_edge.getLaneNumber() == 1 and main_edge.getLength() == 1000.0
    assert main_edge.getLane(0).getWidth() == pytest.approx(6.5)
    assert [tl.getID() for tl in net.getTrafficLights()] == ["meter"]
    assert (tmp_path / "ramp.sumocfg").is_file()


def test_other_lengths_are_exact_and_bad_specs_are_refused(tmp_path):
    net = build_network(tmp_path, NetworkSpec(length=750.0))
    assert edge_lengths(net)["main"] == 750.0
    with pytest.raises(Exception, match="length = -1"):
        NetworkSpec(length=-1)
    with pytest.raises(SumoError, match=r"holds no ramp\.net\.xml"):
        nets_dir(tmp_path / "nowhere")


@pytest.mark.sumo
def test_calibrate_quick_smoke(tmp_path, capsys):
    out = tmp_path / "cal"
    assert main(["calibrate", "--quick", "--horizon", "60", "--jobs", "2",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "R^2" in text and "regime" in text
    data = json.loads((out / "calibration.json").read_text())
    assert set(data["fits"]) == {"h", "a"}
    scenario = tomllib.loads((out / "calibrated_model.toml").read_text())
    assert "ao_max_h" in scenario["model"]
    assert len(load_green_share_curve(out / "meter_curve.toml").green_share) == 2
    assert (out / "calibration.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(("args", "message"), [
    (["calibrate", "--scenario", "missing.toml"], "does not exist"),
    (["calibrate", "--step-length", "3"], "step_length = 3.0 is not allowed"),
    (["build-net", "--out", "/proc/arzsumo-no"], "arzsumo: error"),
])
def test_sumo_user_errors_are_one_line_exit_2(args, message):
    proc = subprocess.run([sys.executable, "-m", "arzsumo.cli", *args], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
