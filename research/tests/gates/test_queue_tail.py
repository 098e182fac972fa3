"""The queue tail read off a speed field whose free stretch is known."""

import numpy as np
import pytest
from arzsumo_studies.gates import PremiseError
from arzsumo_studies.gates.queue_tail import queue_tail

X = np.arange(20) * 50.0 + 25.0                        # 1 km in 50 m cells


def _field(tail_m: float, free=16.0, jam=7.0, periods=60, seed=0):
    rng = np.random.default_rng(seed)
    v = np.where(tail_m > X, free, jam)[None, :] + rng.normal(0, 1.0, (periods, X.size))
    return v


@pytest.mark.parametrize("tail", [0.0, 100.0, 300.0, 650.0])
def test_the_tail_is_the_end_of_the_free_cells_from_the_inlet(tail):
    assert queue_tail(X, _field(tail)) == pytest.approx(tail)


def test_a_congested_section_with_waves_has_no_tail():
    t = np.arange(300)[:, None]
    v = 7.0 + 4.0 * np.sin(2 * np.pi * (t + X[None, :] / 9.0) / 90.0)   # stop and go
    assert queue_tail(X, v) == 0.0


def test_a_free_stretch_downstream_of_a_congested_inlet_is_no_tail():
    v = _field(0.0)
    v[:, 10:] = 16.0
    assert queue_tail(X, v) == 0.0


def test_empty_cells_are_left_out_and_a_bad_field_is_refused():
    v = _field(300.0)
    v[:, 2] = np.nan
    assert queue_tail(X, v) == pytest.approx(300.0)
    with pytest.raises(PremiseError, match="periods x 20 cells"):
        queue_tail(X, v[:, :5])
