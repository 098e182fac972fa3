"""``section.waves`` from a stand-in result (no SUMO): classes, files, units, schema."""

from types import SimpleNamespace

import numpy as np
import pytest

from arzsumo.outputs.waves import waves_summary
from arzsumo.schema import RUN_SUMMARY, key_units
from arzsumo.sumo.lateral import LateralRecord

N_T, N_X, L = 600, 20, 1000.0


def _result() -> SimpleNamespace:
    """A 600 s window: HV speeds with a 3 min wave of 2 m/s, AVs steady; the snapshots
    hold HVs in two steady files (27 and 68 km/h) and AVs in one."""
    t = np.arange(N_T)[:, None]
    micro = np.full((N_T, 4, N_X), 0.05)
    micro[:, 1] = 12.0 + 2.0 * np.sin(2 * np.pi * t / 180.0)
    micro[:, 3] = 4.0
    rng = np.random.default_rng(0)
    counts = np.full(N_T, 30)
    n = counts.sum()
    av = rng.random(n) < 0.3
    right = rng.random(n) < 0.68
    lat = np.where(av, 0.0, np.where(right, -2.0, 2.0)) + rng.normal(0, 0.1, n)
    speed = np.where(av, 14.0, np.where(right, 27.0, 68.0)) / 3.6
    rec = LateralRecord(np.arange(N_T, dtype=float), counts, rng.uniform(0, L, n), speed,
                        lat, av)
    return SimpleNamespace(sumo=SimpleNamespace(control_period=1.0, cell_length=50.0),
                           scenario=SimpleNamespace(params=SimpleNamespace(length=L)),
                           micro=micro, lateral=rec)


def test_the_waves_block_per_class_and_file():
    w = waves_summary(_result(), 10, 2)
    assert (w["block_m"], w["block_s"], w["window_s"]) == (100.0, 10.0, 600.0)
    assert w["snapshots"] == N_T and w["lateral_samples"] == 30 * N_T
    h, a = w["h"], w["a"]
    amp_kmh = 2.0 * 3.6 * np.sinc(10 / 180)
    assert h["band_power_kmh2"] == pytest.approx(amp_kmh ** 2 / 2, rel=0.05)
    assert h["band_share"] > 0.95 and h["oscillation_kmh"] == pytest.approx(
        amp_kmh / np.sqrt(2), rel=0.02)
    assert h["amplitude"]["x_m"] == [50.0 + 100.0 * k for k in range(10)]
    assert abs(h["growth_per_km"]) < 1e-6                # the same everywhere
    assert a["oscillation_kmh"] == 0.0 and a["band_power_kmh2"] == pytest.approx(0.0)
    assert (h["file_count"], a["file_count"]) == (2, 1)
    right, left = h["files"]["0"], h["files"]["1"]
    assert right["share"] + left["share"] == pytest.approx(1.0)
    assert right["share"] == pytest.approx(0.68, abs=0.02)
    assert (right["speed_mean_kmh"], left["speed_mean_kmh"]) == pytest.approx((27.0, 68.0))
    assert right["oscillation_kmh"] == pytest.approx(0.0, abs=1e-9)   # steady files
    assert a["files"]["0"]["share"] == 1.0 and a["files"]["0"]["centre_m"] == pytest.approx(
        0.0, abs=0.02)


def test_every_waves_key_has_a_unit():
    units = key_units({"section": {"waves": waves_summary(_result(), 10, 2)}}, RUN_SUMMARY)
    assert "?" not in units.values(), [k for k, u in units.items() if u == "?"]
    assert units["section.waves.h.band_power_kmh2"] == "(km/h)^2"
    assert units["section.waves.h.files.1.growth_per_km"] == "1/km"
    assert units["section.waves.a.files.0.centre_m"] == "m"
    assert units["section.waves.h.amplitude.sd_kmh"] == "km/h"


def test_a_run_without_snapshots_has_no_files():
    res = _result()
    res.lateral = None
    w = waves_summary(res, 10, 2)
    assert w["snapshots"] == 0 and w["h"]["files"] == {} and w["h"]["file_count"] == 0
