"""The critical-occupancy finder on synthetic flow-occupancy curves with noise."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.evaluation.critical_occupancy import (
    binned_curve,
    critical_occupancy,
    fit_triangle,
    period_means,
)


def _triangle(o: np.ndarray, oc: float = 0.22, qc: float = 0.55, oj: float = 0.8):
    """Flow (veh/s) of a triangular curve: 0 at o = 0 and o = oj, qc at oc."""
    return np.where(o < oc, qc * o / oc, qc * (oj - o) / (oj - oc))


def test_triangular_curve_with_noise_gives_its_peak():
    rng = np.random.default_rng(11)
    o = rng.uniform(0.02, 0.6, 600)
    q = _triangle(o) + rng.normal(0, 0.03, o.size)         # about 110 veh/h of noise
    crit = critical_occupancy(o, q)
    assert crit.critical == pytest.approx(0.22, abs=0.015)
    assert crit.fit.capacity == pytest.approx(0.55, abs=0.02)
    assert crit.target == pytest.approx(0.9 * crit.critical)
    assert crit.saturated and crit.fit.congested_slope < 0 < crit.fit.free_slope
    assert crit.peak_bin == pytest.approx(0.22, abs=0.05)


def test_a_plateau_downstream_of_a_bottleneck_gives_the_knee():
    rng = np.random.default_rng(5)
    o = rng.uniform(0.02, 0.5, 400)
    q = np.minimum(0.55 * o / 0.3, 0.55) + rng.normal(0, 0.02, o.size)
    crit = critical_occupancy(o, q, share=0.95)
    assert crit.critical == pytest.approx(0.3, abs=0.02) and crit.saturated
    assert crit.target == pytest.approx(0.95 * crit.critical)


def test_free_flow_only_gives_a_lower_bound_flagged_as_not_saturated():
    o = np.linspace(0.02, 0.15, 51)
    crit = critical_occupancy(o, 2.5 * o)
    assert not crit.saturated
    assert crit.critical == pytest.approx(np.percentile(o, 98))      # flow still rose there
    assert crit.target == pytest.approx(0.9 * crit.critical)


def test_period_means_and_bins():
    occ = np.r_[np.full(40, 0.1), np.full(40, 0.3), np.full(10, 0.5)]
    o, q = period_means(occ, 2 * occ, dt=1.0, period=40.0)
    np.testing.assert_allclose(o, [0.1, 0.3])               # trailing 10 s dropped
    np.testing.assert_allclose(q, [0.2, 0.6])
    occ[5] = np.nan
    assert period_means(occ, 2 * occ, 1.0, 40.0)[0].tolist() == pytest.approx([0.3])
    centres, mean, count = binned_curve(np.array([0.101, 0.105, 0.31]),
                                        np.array([1.0, 3.0, 5.0]))
    np.testing.assert_allclose(centres, [0.105, 0.315])
    np.testing.assert_allclose(mean, [2.0, 5.0])
    assert count.tolist() == [2, 1]
    with pytest.raises(ValueError, match="whole multiple"):
        period_means(occ, occ, 1.0, 40.5)
    with pytest.raises(ValueError, match="at least 5"):
        fit_triangle(np.ones(3), np.ones(3))
