"""Statistics over seeds on known cases: identical runs, constant shifts, coverage."""

import math

import numpy as np
import pytest
from scipy import stats as sps

from arzsumo.errors import ArzsumoError
from arzsumo.evaluation.stats import (
    MeanCI,
    StatisticsError,
    bootstrap_mean_ci,
    mean_ci,
    paired_difference,
    wins_losses,
)

SEEDS_TTT = np.array([812.4, 799.1, 845.7, 790.3, 820.8, 833.9, 805.2, 811.0, 798.6, 826.4])


def test_identical_runs_give_zero_difference_with_zero_width():
    c = paired_difference(SEEDS_TTT, SEEDS_TTT.copy())
    for ci in (c.t, c.bootstrap):
        assert ci.mean == 0.0 and ci.low == 0.0 and ci.high == 0.0 and ci.width == 0.0
        assert ci.n == 10 and ci.n_dropped == 0
    assert (c.wins, c.losses, c.ties) == (0, 0, 10)


@pytest.mark.parametrize("shift", [-37.25, 0.1, 1e4 / 3])
def test_constant_shift_is_recovered_exactly(shift):
    c = paired_difference(SEEDS_TTT + shift, SEEDS_TTT)
    assert c.mean_diff == pytest.approx(shift, rel=1e-12, abs=1e-12)
    assert c.t.width == 0.0 and c.bootstrap.width == 0.0
    assert c.t.low == c.t.mean == c.t.high
    worse = shift > 0       # lower is better: a positive shift loses on every seed
    assert (c.wins, c.losses, c.ties) == ((0, 10, 0) if worse else (10, 0, 0))


def test_t_interval_matches_the_textbook_formula():
    x = np.array([3.0, 5.0, 4.0, 8.0])
    ci = mean_ci(x)
    half = sps.t.ppf(0.975, 3) * np.std(x, ddof=1) / 2.0
    assert ci.mean == 5.0
    assert ci.low == pytest.approx(5.0 - half, rel=1e-14)
    assert ci.high == pytest.approx(5.0 + half, rel=1e-14)
    assert half == pytest.approx(3.182446 * math.sqrt(14 / 3) / 2, rel=1e-6)  # 3.4374


def test_t_coverage_on_normal_data_is_within_the_binomial_band():
    rng = np.random.default_rng(2024)
    reps, mu = 2000, 3.0
    hits = sum(mean_ci(rng.normal(mu, 2.0, 10)).covers(mu) for _ in range(reps))
    sd = math.sqrt(0.95 * 0.05 / reps)
    assert abs(hits / reps - 0.95) <= 3 * sd, hits / reps


@pytest.mark.parametrize("method", ["BCa", "percentile"])
def test_bootstrap_coverage_is_roughly_nominal(method):
    # measured 0.92 over 3000 replications (n = 20): the bootstrap under-covers a little at
    # small n; the band is loose on purpose (600 replications, sd about 0.011)
    rng = np.random.default_rng(7)
    reps, mu = 600, -1.5
    hits = sum(bootstrap_mean_ci(rng.normal(mu, 2.0, 20), method=method, n_resamples=1999,
                                 seed=i).covers(mu) for i in range(reps))
    assert 0.88 <= hits / reps <= 0.97, hits / reps


def test_bootstrap_is_seeded_and_brackets_the_mean():
    rng = np.random.default_rng(3)
    x = rng.normal(0.0, 1.0, 15)
    a, b = bootstrap_mean_ci(x, seed=5), bootstrap_mean_ci(x, seed=5)
    assert a == b and a.low < a.mean < a.high and a.method == "BCa"
    assert bootstrap_mean_ci(x, seed=6).low != a.low


def test_wins_losses_and_ties_are_counted_per_seed():
    treat = np.array([10.0, 12.0, 9.0, 11.0, 10.0, 7.0])
    base = np.array([11.0, 11.0, 9.0, 10.5, 10.05, 8.0])
    assert wins_losses(treat - base) == (3, 2, 1)  # 10.0 vs 10.05 is a win at tol 0
    c = paired_difference(treat, base, tie_tol=0.1)
    assert (c.wins, c.losses, c.ties) == (2, 2, 2)
    c = paired_difference(treat, base, tie_tol=0.1, lower_is_better=False)
    assert (c.wins, c.losses, c.ties) == (2, 2, 2)
    assert wins_losses(treat - base, lower_is_better=False) == (2, 3, 1)


def test_one_seed_gives_an_undefined_interval():
    c = paired_difference([5.0], [3.0])
    assert c.mean_diff == 2.0 and c.n == 1
    assert math.isnan(c.t.low) and math.isnan(c.bootstrap.high)
    assert not c.t.interval_defined and not c.t.covers(2.0)
    assert (c.wins, c.losses, c.ties) == (0, 1, 0)


def test_nan_seeds_are_dropped_pairwise_and_counted():
    treat = np.array([1.0, np.nan, 3.0, 4.0, 6.0])
    base = np.array([0.5, 2.0, np.nan, 3.0, 5.0])
    c = paired_difference(treat, base)
    assert c.n == 3 and c.t.n_dropped == 2 and c.bootstrap.n_dropped == 2
    assert c.mean_diff == pytest.approx((0.5 + 1.0 + 1.0) / 3)
    assert c.wins + c.losses + c.ties == 3
    m = mean_ci([1.0, np.nan, 3.0])
    assert (m.mean, m.n, m.n_dropped) == (2.0, 2, 1)


@pytest.mark.parametrize(("args", "match"), [
    (([1.0, 2.0], [1.0]), "treatment has 2 values and baseline 1"),
    (([1.0, np.inf], [1.0, 2.0]), r"treatment = \[1.0, inf\] is not allowed"),
    (([np.nan, np.nan], [1.0, 2.0]), "at least one value not NaN"),
    ((np.ones((2, 2)), np.ones((2, 2))), r"has shape \(2, 2\); expected one value per seed"),
])
def test_unusable_data_is_refused(args, match):
    with pytest.raises(StatisticsError, match=match) as info:
        paired_difference(*args)
    assert isinstance(info.value, ArzsumoError) and isinstance(info.value, ValueError)


def test_records_check_themselves():
    with pytest.raises(StatisticsError, match=r"level = 1\.5"):
        MeanCI(1.0, 0.0, 2.0, 3, level=1.5)
    with pytest.raises(StatisticsError, match="method = 'bca'"):
        bootstrap_mean_ci([1.0, 2.0], method="bca")
