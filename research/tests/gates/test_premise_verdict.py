"""Gate 5, the operating point, and the verdict over seeds."""

import json
import math

import numpy as np
import pytest
from arzsumo_studies.gates import (
    GateResult,
    PremiseError,
    PremiseThresholds,
    inserted_gate,
    premise_verdict,
    ramp_demand_gate,
    ramp_queue_gate,
    stationarity_gate,
    summarise_seeds,
)

from arzsumo.evaluation.stationarity import count_trend


def test_the_stationarity_gate_reads_the_count_trend():
    flat = stationarity_gate(count_trend(np.full(450, 140.0), 1.0))
    assert flat.passed and flat.value == 1.0 and flat.detail["stationary"]
    assert json.loads(json.dumps(flat.as_dict()))["detail"]["blocks"] == 15
    rising = stationarity_gate(count_trend(140.0 + np.arange(450.0) / 30.0, 1.0))
    assert not rising.passed and rising.value == 0.0
    assert rising.detail["drift"] == pytest.approx(15.0 / 147.5, rel=1e-3)
    assert stationarity_gate(np.bool_(True)).passed
    with pytest.raises(PremiseError, match=r"trend = 0\.5 is not allowed"):
        stationarity_gate(0.5)                               # type: ignore[arg-type]


@pytest.mark.parametrize(("inserted", "passed"), [(990, True), (980, True), (979, False)])
def test_the_inserted_share_must_reach_98_percent(inserted, passed):
    g = inserted_gate(inserted, 1000)
    assert g.value == pytest.approx(inserted / 1000) and g.passed is passed


def test_the_ramp_demand_and_queue_must_fit_the_meter():
    assert ramp_demand_gate(0.25, 0.5).passed                # 900 of 1800 veh/h
    g = ramp_demand_gate(0.6, 0.5)
    assert not g.passed and g.value == pytest.approx(1.2)
    assert ramp_queue_gate(30, 40).passed and not ramp_queue_gate(41, 40).passed
    with pytest.raises(PremiseError, match="ramp_queue = 0 is not allowed: a finite queue > 0"):
        ramp_queue_gate(3, 0)
    with pytest.raises(PremiseError, match="inserted = -1"):
        inserted_gate(-1, 10)


def _gate(name, value, passed):
    return GateResult(name, value, 1.0, passed)


def test_a_gate_over_seeds_gives_its_share_and_a_t_interval():
    values = [1.2, 1.4, 1.1, 0.9, 1.3]
    s = summarise_seeds([_gate("amplification[hv]", v, v >= 1.0) for v in values])
    assert (s.seeds, s.passed_seeds, s.share, s.passed) == (5, 4, 0.8, True)
    assert s.value.mean == pytest.approx(1.18)
    half = 2.7764451 * np.std(values, ddof=1) / math.sqrt(5)       # t(0.975, 4)
    assert (s.value.low, s.value.high) == pytest.approx((1.18 - half, 1.18 + half))
    s3 = summarise_seeds([_gate("x", v, v >= 1.2) for v in values])
    assert s3.share == pytest.approx(0.6) and not s3.passed
    nan = summarise_seeds([_gate("waves[hv]", math.nan, False)] * 2)
    assert nan.value is None and nan.as_dict()["n"] == 0
    with pytest.raises(PremiseError, match="results of one gate"):
        summarise_seeds([_gate("a", 1.0, True), _gate("b", 1.0, True)])


def test_the_verdict_applies_the_rule_and_keeps_the_model_apart():
    seeds = [[_gate("coupling[hv]", 0.5, True), _gate("pulse", math.nan, True),
              _gate("model_wave[hv]", 1.6, False)] for _ in range(4)]
    seeds.append([_gate("coupling[hv]", 5.0, False), _gate("pulse", 80.0, False)])
    v = premise_verdict(seeds)
    assert [g.name for g in v.premise] == ["coupling[hv]", "pulse"]
    assert [g.name for g in v.model] == ["model_wave[hv]"]
    assert v.passed and not v.model_passed and v.failed == ("model_wave[hv]",)
    assert v.model[0].seeds == 4                     # judged over the seeds that measured it
    assert "80%" in v.rule
    strict = premise_verdict(seeds, PremiseThresholds(seed_share=1.0))
    assert not strict.passed and strict.failed == ("coupling[hv]", "pulse", "model_wave[hv]")
    d = strict.as_dict()
    assert d["premise"][0]["share"] == 0.8 and d["passed"] is False
    with pytest.raises(PremiseError, match="each gate at most once per seed"):
        premise_verdict([[_gate("pulse", 1.0, True), _gate("pulse", 1.0, True)]])
