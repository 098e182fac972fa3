"""Sensor records check themselves; synthetic sensors read what the field holds."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.errors import ModelError
from arzsumo.estimate.observations import (
    LoopNoise,
    LoopObservation,
    ProbeNoise,
    ProbeObservation,
    density_from_occupancy,
)
from arzsumo.estimate.synthetic import interpolate_loops, sample_loops, sample_probes

GOOD = {"t": 10.0, "period": 1.0, "x": [0.0, 500.0], "flow": np.ones((2, 2)),
        "speed": np.full((2, 2), 10.0), "density": np.full((2, 2), 0.05)}


@pytest.mark.parametrize(("change", "name"), [
    ({"x": [500.0, 0.0]}, "x"), ({"flow": np.ones((2, 3))}, "flow"),
    ({"period": 0.0}, "period"), ({"density": np.full((2, 2), np.nan)}, "flow/density"),
])
def test_a_bad_loop_record_names_its_field(change, name):
    with pytest.raises(ModelError, match=name):
        LoopObservation(**{**GOOD, **change})


def test_records_are_read_only_and_speeds_may_be_missing():
    obs = LoopObservation(**{**GOOD, "speed": [[10.0, np.nan], [9.0, 8.0]]})
    with pytest.raises(ValueError):
        obs.flow[0, 0] = 3.0
    assert obs.t_mid == 9.5
    with pytest.raises(ModelError, match="cls"):
        ProbeObservation(0.0, "bus", [1.0], [2.0])
    with pytest.raises(ModelError, match="speed"):
        ProbeNoise(speed=-1.0)
    with pytest.raises(ModelError, match="density"):
        LoopNoise(density=0.0)
    assert density_from_occupancy(0.3, 7.5) == pytest.approx(0.04)


def test_synthetic_sensors_read_the_field():
    x = np.linspace(5.0, 995.0, 100)
    fields = np.vstack([0.05 + 0.02 * x / 1000, np.full(100, 12.0), np.full(100, 0.03),
                        np.full(100, 8.0)])
    loops = sample_loops(x, fields, np.array([0.0, 500.0, 1000.0]), 1.0, 1.0, LoopNoise(),
                         None)
    np.testing.assert_allclose(loops.density[0], [0.0501, 0.06, 0.0699])
    np.testing.assert_allclose(loops.flow[1], 0.24)
    back = interpolate_loops(loops, np.array([250.0, 500.0, 2000.0]))
    np.testing.assert_allclose(back[0], [0.05505, 0.06, 0.0699])
    np.testing.assert_allclose(back[3], 8.0)
    rng = np.random.default_rng(0)
    probes = sample_probes(x, fields, "a", 1.0, 1.0, ProbeNoise(), rng)
    assert probes.x.size in (29, 30)                     # 0.03 veh/m on 1 km (990 m of cells)
    assert abs(probes.v.mean() - 8.0) < 0.5
    half = sample_probes(x, fields, "a", 0.5, 1.0, ProbeNoise(), np.random.default_rng(1))
    assert 5 <= half.x.size <= 25
