"""What a run keeps of SUMO: its FCD output and the configuration it ran, with real SUMO.

One short open-loop run through ``arzsumo run --fcd`` records libsumo's vehicle count
after every step; the FCD file must hold the same count per time step. The kept
``run.sumocfg``, run by the plain ``sumo`` binary for the warm-up, must load the same
vehicles and, the fixed-cycle meter's nominal plan being a static program there, move
them exactly as the run did. The same run through TraCI gives the same numbers.
"""

from __future__ import annotations

import gzip
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.session import prepare_run
from arzsumo.cli import main
from arzsumo.outputs.bridge import write_results
from arzsumo.resources import shipped_nets_dir
from arzsumo.scenario import load_scenario
from arzsumo.sumo.demand import route_file_text
from arzsumo.sumo.network_measures import FCD_ATTRIBUTES, read_statistics, read_trips
from arzsumo.sumo.paths import NET_FILE, sumo_binary
from arzsumo.sumo.simulation import SumoSimulation

LEGACY = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
WARMUP, HORIZON, SEED = 20.0, 10.0, 1
pytestmark = pytest.mark.sumo


def fcd_steps(path: Path) -> dict[float, list[dict[str, str]]]:
    """Vehicles (their attributes) per ``<timestep>`` of an FCD file (gzip or plain)."""
    opener = gzip.open if path.suffix == ".gz" else open
    out: dict[float, list[dict[str, str]]] = {}
    with opener(path, "rb") as f:
        for _, el in ET.iterparse(f, events=("end",)):
            if el.tag == "timestep":
                out[float(el.get("time"))] = [dict(v.attrib) for v in el]
                el.clear()
    return out


def _recording(monkeypatch) -> list[tuple[float, int]]:
    """(time after the step, vehicles on the network) after every SUMO step."""
    counts: list[tuple[float, int]] = []
    step = SumoSimulation.step

    def recorded(self):
        t = step(self)
        counts.append((t, int(self.lib.vehicle.getIDCount())))
        return t

    monkeypatch.setattr(SumoSimulation, "step", recorded)
    return counts


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("fcd") / "run"
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        counts = _recording(mp)
        code = main(["run", str(LEGACY), "--controller", "open", "--seed", str(SEED),
                     "--warmup", str(WARMUP), "--horizon", str(HORIZON), "--fcd",
                     "--no-plots", "--quiet", "--out", str(out)])
    assert code == 0
    return out, counts


def test_fcd_counts_every_vehicle_of_every_step_as_libsumo_does(run):
    out, counts = run
    steps = fcd_steps(out / "fcd.xml.gz")
    dt = load_scenario(LEGACY).sumo.step_length
    assert len(steps) == len(counts) == round((WARMUP + HORIZON) / dt)
    # SUMO writes a step's output under the time the step began: libsumo's time is its end
    for t, n in counts:
        assert len(steps[round(t - dt, 6)]) == n, t
    assert max(n for _, n in counts) > 20


def test_fcd_records_the_lateral_position_speed_lane_and_type(run):
    out, _ = run
    vehicles = [v for vs in fcd_steps(out / "fcd.xml.gz").values() for v in vs]
    assert set(vehicles[0]) == {"id", *FCD_ATTRIBUTES}
    lat = np.array([float(v["posLat"]) for v in vehicles if v["lane"] == "main_0"])
    assert lat.min() < -1.0 < 1.0 < lat.max()       # the HV columns at both lane edges
    assert {v["type"] for v in vehicles} == {"hv", "av"}


def test_the_kept_configuration_holds_the_files_the_run_read(run):
    out, _ = run
    sc = load_scenario(LEGACY)
    cfg = sc.sumo.with_(seed=SEED, horizon=WARMUP + HORIZON)
    sumo = out / "sumo"
    assert (sumo / "run.rou.xml").read_text() == route_file_text(sc.params, cfg)
    assert (sumo / NET_FILE).read_bytes() == (shipped_nets_dir() / NET_FILE).read_bytes()
    root = ET.parse(out / "run.sumocfg").getroot()
    adds = root.find("input/additional-files").get("value").split(",")
    # the legacy scenario has no section loops: ALINEA's loop on down and the meter's plan
    assert adds == ["sumo/e1_down.add.xml", "sumo/meter.add.xml"]
    program = ET.parse(out / adds[-1]).getroot().find("tlLogic")
    assert [(p.get("duration"), p.get("state")) for p in program] == [("3", "G"), ("3", "r")]


def test_plain_sumo_on_the_kept_configuration_repeats_the_warm_up(run, tmp_path):
    out, _ = run
    cmd = [str(sumo_binary("sumo")), "-c", str(out / "run.sumocfg"), "--end", f"{WARMUP:g}",
           "--fcd-output", str(tmp_path / "fcd.xml"),
           "--fcd-output.attributes", ",".join(FCD_ATTRIBUTES),
           "--statistic-output", str(tmp_path / "stats.xml"), "--no-step-log", "true",
           "--no-warnings", "true"]
    subprocess.run(cmd, check=True, capture_output=True, timeout=60)
    trips = read_trips_gz(out / "tripinfo.xml.gz", tmp_path)
    end = WARMUP + HORIZON
    due = np.where(trips["depart_s"] >= 0, trips["depart_s"], end) - trips["depart_delay_s"]
    stats = read_statistics(tmp_path / "stats.xml")
    assert stats["loaded"] == int(np.sum(due < WARMUP - 1e-9)) > 20
    assert stats["inserted"] > 20
    # the open loop's fixed cycle is the static program: the warm-up moves alike
    again, ran = fcd_steps(tmp_path / "fcd.xml"), fcd_steps(out / "fcd.xml.gz")
    assert len(again) == round(WARMUP / load_scenario(LEGACY).sumo.step_length)
    assert all(again[t] == ran[t] for t in again)


def read_trips_gz(path: Path, tmp: Path):
    plain = tmp / "tripinfo.xml"
    plain.write_bytes(gzip.decompress(path.read_bytes()))
    return read_trips(plain)


def test_traci_gives_the_numbers_of_libsumo(run, monkeypatch, tmp_path):
    out, counts = run
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path / "cache"))
    sc = load_scenario(LEGACY)
    run = prepare_run(sc, controller="open", warmup=WARMUP, horizon=HORIZON, seed=SEED,
                      fcd=True)
    traci_counts = _recording(monkeypatch)
    res = run_cosimulation(run, frontend="traci")
    assert traci_counts == counts                               # bit-identical per step
    path, _ = write_results(res, tmp_path / "traci", "# test\n", plots=False)
    assert fcd_steps(path / "fcd.xml.gz") == fcd_steps(out / "fcd.xml.gz")
    a, b = (pq.read_table(p / "periods.parquet").to_pandas() for p in (path, out))
    assert a.equals(b)
