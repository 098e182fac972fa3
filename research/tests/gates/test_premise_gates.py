"""The premise gates' shared records: thresholds and results check themselves."""

import math

import pytest
from arzsumo_studies.gates import GateResult, PremiseError, PremiseThresholds

from arzsumo.errors import ArzsumoError


def test_the_defaults_are_the_documented_ones():
    th = PremiseThresholds()
    assert th.file_speed_gap == pytest.approx(10.0 / 3.6)
    assert th.gain_range == (-1.3, -0.7)
    assert th.pulse_decay_fraction == pytest.approx(math.exp(-1.0))
    assert (th.model_wave_tolerance, th.min_inserted, th.seed_share) == (0.25, 0.98, 0.8)
    assert (th.wave_min_r2, th.wave_min_pairs, th.pulse_round_trips) == (0.9, 3, 2.0)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"file_speed_gap": -1.0}, "file_speed_gap = -1.0 is not allowed: a finite number > 0"),
    ({"file_speed_gap": math.inf}, "file_speed_gap = inf"),
    ({"wave_min_r2": 1.5}, "wave_min_r2 = 1.5 is not allowed: a number in \\(0, 1\\)"),
    ({"pulse_decay_fraction": 1.0}, "pulse_decay_fraction"),
    ({"seed_share": 1.2}, "seed_share = 1.2 is not allowed: a number in \\(0, 1\\]"),
    ({"wave_min_pairs": 2}, "wave_min_pairs = 2 is not allowed: an integer >= 3"),
    ({"gain_range": (-0.7, -1.3)}, "gain_range .* low < high"),
    ({"gain_range": (-1.0,)}, "gain_range"),
])
def test_bad_thresholds_are_refused_naming_the_field(kwargs, match):
    with pytest.raises(PremiseError, match=match):
        PremiseThresholds(**kwargs)


def test_a_gate_result_is_a_frozen_checked_record():
    g = GateResult("coupling[hv]", 1, 2.0, True, {"files": 1})
    assert g.value == 1.0 and isinstance(g.value, float)
    assert g.as_dict() == {"name": "coupling[hv]", "value": 1.0, "threshold": 2.0,
                           "passed": True, "detail": {"files": 1}}
    assert GateResult("actuator", -1.0, (-1.3, -0.7), False).as_dict()["threshold"] == \
        [-1.3, -0.7]
    with pytest.raises(AttributeError):
        g.passed = False                                    # type: ignore[misc]
    with pytest.raises(PremiseError, match="name = '' is not allowed"):
        GateResult("", 1.0, 1.0, True)
    with pytest.raises(PremiseError, match="passed = 'yes'"):
        GateResult("x", 1.0, 1.0, "yes")                     # type: ignore[arg-type]
    assert issubclass(PremiseError, ArzsumoError) and issubclass(PremiseError, ValueError)
