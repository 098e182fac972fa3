"""SUMO's network measures in every ``arzsumo run``: accounting, time spent against the
integral of vehicles in the system over the control window, red against green meter."""

import gzip
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from arzsumo.cli import main
from arzsumo.sumo.network_measures import read_trips
from arzsumo.sumo.simulation import SumoSimulation

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "scenarios" / "legacy_default.toml"
WARMUP, HORIZON, STEP = 40.0, 60.0, 0.1
pytestmark = pytest.mark.sumo


def _scenario(tmp: Path, green_share: float) -> Path:
    text = DEFAULT.read_text(encoding="utf-8")
    text = text.replace("green_share = 0.5 ", f"green_share = {green_share} ")
    text = text.replace("warmup_s = 150", f"warmup_s = {WARMUP:g}")
    text = text.replace("kernel_cells = 100", "kernel_cells = 40").replace(
        "twin_cells = 100", "twin_cells = 40")
    assert f"green_share = {green_share} " in text and f"warmup_s = {WARMUP:g}" in text
    path = tmp / f"green{green_share:g}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _run(tmp: Path, green_share: float, monkeypatch) -> tuple[dict, dict, Path]:
    """``arzsumo run`` (open loop) of the meter at ``green_share``; its summary, the
    per-step integral (libsumo, s) of vehicles in the system over the control window by
    origin, and the results directory."""
    integral = {"mainline": 0.0, "ramp": 0.0}
    step = SumoSimulation.step

    def counting(sim: SumoSimulation) -> float:
        t = step(sim)
        if t > WARMUP + 1e-6:    # the step (t - dt, t] lies in the control window
            ids = [*sim.lib.vehicle.getIDList(), *sim.lib.simulation.getPendingVehicles()]
            ramp = sum(1 for v in ids if v.startswith("ramp"))
            integral["ramp"] += ramp * STEP
            integral["mainline"] += (len(ids) - ramp) * STEP
        return t

    monkeypatch.setattr(SumoSimulation, "step", counting)
    out = tmp / f"run{green_share:g}"
    assert main(["run", str(_scenario(tmp, green_share)), "--controller", "open",
                 "--horizon", f"{HORIZON:g}", "--quiet", "--no-plots", "--out",
                 str(out)]) == 0
    monkeypatch.undo()
    integral["total"] = integral["mainline"] + integral["ramp"]
    return json.loads((out / "summary.json").read_text()), integral, out


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("window")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp / "cache"))
        return {"red": _run(tmp, 0.0, mp), "green": _run(tmp, 1.0, mp)}


@pytest.mark.parametrize("light", ["red", "green"])
def test_accounting_closes_in_the_window_and_the_whole_run(runs, light):
    summ = runs[light][0]
    for key in ("network", "network_whole_run"):
        veh = summ[key]["vehicles"]
        for part in ("mainline", "ramp", "total"):
            assert (veh["completed"][part] + veh["en_route"][part] + veh["waiting"][part]
                    == veh["loaded"][part]), (key, part)
        assert veh["loaded"]["total"] == veh["loaded"]["mainline"] + veh["loaded"]["ramp"]
    net, whole = summ["network"], summ["network_whole_run"]
    assert net["begin_s"] == WARMUP and whole["begin_s"] == 0.0
    assert net["end_s"] == whole["end_s"] == WARMUP + HORIZON
    # same vehicles at the end; the window leaves out those that arrived in the warm-up
    for state in ("en_route", "waiting"):
        assert net["vehicles"][state] == whole["vehicles"][state]
    arrived_in_warmup = whole["vehicles"]["completed"]["total"] - \
        net["vehicles"]["completed"]["total"]
    assert net["vehicles"]["loaded"]["total"] == \
        whole["vehicles"]["loaded"]["total"] - arrived_in_warmup
    assert 0 < net["vehicles"]["in_system_at_start"]["total"] < net["vehicles"]["loaded"]["total"]
    # SUMO's loaded count is what was requested (no drift of the flow periods)
    assert summ["requested"] == whole["vehicles"]["loaded"]["total"]
    assert summ["inserted"] + summ["waiting"] == summ["requested"]


@pytest.mark.parametrize("light", ["red", "green"])
def test_window_time_spent_is_the_integral_of_vehicles_in_the_system(runs, light):
    summ, integral, _ = runs[light]
    net = summ["network"]
    for part in ("mainline", "ramp", "total"):
        loaded = net["vehicles"]["loaded"][part]
        spent = net["time_spent_s"][part]
        assert integral[part] > 100.0
        assert abs(spent - integral[part]) <= STEP * loaded, (part, spent, integral[part])
    # the whole run holds more time than the window; the window's time loss lies in it
    assert net["time_spent_s"]["total"] < summ["network_whole_run"]["time_spent_s"]["total"]
    assert 0 < net["time_loss_s"]["total"] < summ["network_whole_run"]["time_loss_s"]["total"]


def test_red_meter_moves_delay_from_the_mainline_to_the_ramp(runs):
    red, green = runs["red"][0]["network"], runs["green"][0]["network"]
    ramp_red = red["depart_delay_s"]["ramp"] + red["waiting_time_s"]["ramp"]
    ramp_green = green["depart_delay_s"]["ramp"] + green["waiting_time_s"]["ramp"]
    assert ramp_red > ramp_green + 500.0, (ramp_red, ramp_green)
    assert red["time_loss_s"]["mainline"] < 0.7 * green["time_loss_s"]["mainline"]
    assert red["throughput_veh_h"]["section_outlet"] > green["throughput_veh_h"]["section_outlet"]
    assert runs["red"][0]["plan_changes"] == runs["green"][0]["plan_changes"] == 0


def test_section_speed_sd_and_the_kept_tripinfo(runs):
    summ, _, out = runs["green"]
    sec = summ["section"]
    assert sec["TTT"] == summ["TTT"] and sec["J_fuel"] == summ["J_fuel"]
    for c in ("h", "a"):
        # every vehicle on main every step of the window, sampled at 0.1 s
        assert sec["speed_samples"][c] > 10 * HORIZON
        assert 0.0 < sec["speed_sd_kmh"][c] < 60.0
        assert 0.0 < sec["speed_mean_kmh"][c] < 100.0
    assert summ["units_by_key"]["section.speed_sd_kmh.h"] == "km/h"
    assert summ["units_by_key"]["network.time_spent_s.total"] == "veh*s"
    # SUMO's tripinfo is kept, compressed, and rereads to the whole-run figures
    raw = out / "tripinfo.xml.gz"
    assert raw.stat().st_size < 200_000
    plain = out / "tripinfo.xml"
    plain.write_bytes(gzip.decompress(raw.read_bytes()))
    trips = read_trips(plain)
    whole = summ["network_whole_run"]
    assert len(trips) == whole["vehicles"]["loaded"]["total"]
    assert trips["time_spent_s"].sum() == pytest.approx(whole["time_spent_s"]["total"])


def test_speed_oscillation_recomputed_from_the_written_cells(runs):
    """The summary's oscillation equals one recomputed with pandas from cells.parquet:
    100 m x 10 s block means of the micro speed, sd over time per block column (ddof 1),
    RMS over columns, in km/h; it leaves out the profile, so it lies below the pooled sd."""
    summ, _, out = runs["green"]
    sec = summ["section"]
    assert (sec["oscillation_block_m"], sec["oscillation_block_s"]) == (100.0, 10.0)
    cells = pd.read_parquet(out / "cells.parquet")
    micro = cells[cells["source"] == "micro"].copy()
    periods, places = np.unique(micro["t_s"]), np.unique(micro["x_m"])
    micro["bt"] = np.searchsorted(periods, micro["t_s"]) // 10      # 1 s periods
    micro["bx"] = np.searchsorted(places, micro["x_m"]) // 2        # 50 m cells
    # incomplete trailing blocks are left out
    micro = micro[(micro["bt"] < periods.size // 10) & (micro["bx"] < places.size // 2)]
    for c in ("h", "a"):
        blocks = micro.groupby(["bt", "bx"])[f"v_{c}"].mean()
        sd = blocks.groupby(level="bx").std(ddof=1)
        expected = float(np.sqrt(np.mean(sd.dropna() ** 2))) * 3.6
        assert sec["speed_oscillation_kmh"][c] == pytest.approx(expected, rel=1e-9)
        assert 0.0 < sec["speed_oscillation_kmh"][c] < sec["speed_sd_kmh"][c]
    assert summ["units_by_key"]["section.speed_oscillation_kmh.a"] == "km/h"


def test_speed_wave_recomputed_from_the_written_cells(runs):
    """The waves' direction in the summary equals a pandas recomputation from cells.parquet:
    per lag, the correlation of upstream speeds with downstream ones shifted by the lag,
    averaged over the pairs of places 250 m apart; the lag of the peak."""
    summ, _, out = runs["green"]
    wave = summ["section"]["speed_wave"]
    cells = pd.read_parquet(out / "cells.parquet")
    micro = cells[cells["source"] == "micro"]
    max_lag = min(150, micro["t_s"].nunique() // 2)
    assert wave["gap_m"] == 250.0
    for c in ("h", "a"):
        field = micro.pivot(index="t_s", columns="x_m", values=f"v_{c}")
        field = field.interpolate(limit_direction="both").reset_index(drop=True)
        pairs = [(field.iloc[:, j], field.iloc[:, j + 5]) for j in range(field.shape[1] - 5)
                 if field.iloc[:, [j, j + 5]].notna().all().all()]
        corr = pd.DataFrame({k: [up.corr(down.shift(-k)) for up, down in pairs]
                             for k in range(-max_lag, max_lag + 1)})
        corr = corr[corr.notna().any(axis=1)]          # constant series: no correlation
        mean = corr.mean(axis=0)
        got = wave[c]
        assert got["pairs"] == len(corr)
        assert got["lag_s"] == float(mean.idxmax())
        assert got["peak_corr"] == pytest.approx(float(mean.max()), rel=1e-9)
        resolved = 2 <= abs(got["lag_s"]) < max_lag
        assert (got["speed_kmh"] == pytest.approx(250.0 / got["lag_s"] * 3.6) if resolved
                else got["speed_kmh"] is None or np.isnan(got["speed_kmh"]))
