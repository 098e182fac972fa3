"""Gate 1, the coupled stream, on synthetic vehicle samples with known answers."""

import json

import numpy as np
import pytest
from arzsumo_studies.gates import PremiseError, coupling_gate, within_block_share
from hypothesis import given, settings
from hypothesis import strategies as st

KMH = 1 / 3.6
N_BLOCK, PER_BLOCK = (60, 10), 100            # 600 s x 1000 m in 10 s x 100 m blocks


def _samples(rng, speeds_kmh, lats, block_sd=2.0, noise_sd=0.5):
    """PER_BLOCK samples in every 10 s x 100 m block, each in one of the files (equal
    shares) at its lateral offset and speed, plus a block effect (sd ``block_sd``, m/s,
    the same for every vehicle of a block) and vehicle noise (``noise_sd``, m/s)."""
    bt, bx = np.meshgrid(np.arange(N_BLOCK[0]), np.arange(N_BLOCK[1]), indexing="ij")
    bt, bx = np.repeat(bt.ravel(), PER_BLOCK), np.repeat(bx.ravel(), PER_BLOCK)
    n = bt.size
    t = (bt + rng.uniform(0, 1, n)) * 10.0
    x = (bx + rng.uniform(0, 1, n)) * 100.0
    f = rng.integers(0, len(speeds_kmh), n)
    effect = rng.normal(0.0, block_sd, N_BLOCK).ravel()
    v = (np.asarray(speeds_kmh)[f] * KMH + effect[bt * N_BLOCK[1] + bx]
         + rng.normal(0.0, noise_sd, n))
    lat = np.asarray(lats, float)[f] + rng.normal(0.0, 0.08, n)
    return t, x, lat, v


def test_two_files_at_27_and_68_kmh_fail_and_the_within_share_is_analytic():
    t, x, lat, v = _samples(np.random.default_rng(1), [27.0, 68.0], [-1.2, 1.2])
    g = coupling_gate(t, x, lat, v, "hv")
    assert g.name == "coupling[hv]" and not g.passed
    assert g.value == pytest.approx(41.0 * KMH, abs=0.1)       # 11.4 m/s
    assert g.detail["n_files"] == 2
    assert [f["share"] for f in g.detail["files"]] == pytest.approx([0.5, 0.5], abs=0.01)
    assert g.detail["files"][0]["speed_mean_ms"] == pytest.approx(27 * KMH, abs=0.1)
    # within: the files' mix p(1-p) D^2 and the noise; between: the block effect
    within = (0.25 * (41.0 * KMH) ** 2 + 0.5 ** 2) * (1 - 1 / PER_BLOCK)
    assert g.detail["within_share"] == pytest.approx(within / (within + 2.0 ** 2), abs=0.01)
    assert g.detail["within_share"] == pytest.approx(0.89, abs=0.01)
    assert json.loads(json.dumps(g.as_dict()))["detail"]["n_files"] == 2


def test_one_file_passes_with_a_low_within_share():
    rng = np.random.default_rng(2)
    t, x, lat, v = _samples(rng, [40.0], [0.0])
    lat = rng.normal(0.0, 0.3, lat.size)                       # one broad file
    g = coupling_gate(t, x, lat, v, "av")
    assert g.passed and g.value == 0.0 and g.detail["n_files"] == 1
    within = 0.5 ** 2 * (1 - 1 / PER_BLOCK)
    assert g.detail["within_share"] == pytest.approx(within / (within + 4.0), abs=0.01)


def test_two_files_at_one_speed_are_one_stream():
    t, x, lat, v = _samples(np.random.default_rng(3), [40.0, 43.0], [-1.2, 1.2])
    g = coupling_gate(t, x, lat, v, "hv")
    assert g.detail["n_files"] == 2 and g.passed
    assert g.value == pytest.approx(3.0 * KMH, abs=0.05)


def test_the_gap_is_judged_against_the_threshold():
    from arzsumo_studies.gates import PremiseThresholds

    t, x, lat, v = _samples(np.random.default_rng(4), [40.0, 52.0], [-1.2, 1.2])
    assert not coupling_gate(t, x, lat, v).passed                          # 12 > 10 km/h
    assert coupling_gate(t, x, lat, v, thresholds=PremiseThresholds(
        file_speed_gap=15 * KMH)).passed


@settings(max_examples=30, deadline=None)
@given(shift=st.floats(-20, 20), scale=st.floats(0.1, 10), seed=st.integers(0, 2**16))
def test_the_within_share_is_a_share_unmoved_by_units_or_offsets(shift, scale, seed):
    rng = np.random.default_rng(seed)
    t, x, v = rng.uniform(0, 100, 300), rng.uniform(0, 500, 300), rng.normal(10, 3, 300)
    share = within_block_share(t, x, v)
    assert 0.0 <= share <= 1.0
    assert within_block_share(t, x, shift + scale * v) == pytest.approx(share, rel=1e-9)


def test_uniform_blocks_have_nothing_within_and_mismatched_samples_are_refused():
    rng = np.random.default_rng(5)
    t, x = rng.uniform(0, 100, 500), rng.uniform(0, 500, 500)
    v = 10.0 + np.floor(t / 10) + 2 * np.floor(x / 100)       # one speed per block
    assert within_block_share(t, x, v) == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(within_block_share(t, x, np.full(500, 3.0)))
    with pytest.raises(PremiseError, match="lat = '4 samples'"):
        coupling_gate(t, x, np.zeros(4), v)
