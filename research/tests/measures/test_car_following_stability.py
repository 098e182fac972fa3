"""The string-stability prediction at a measured operating point: SUMO's ACC gap law and
IDM's derivatives, the lateral files, the growth over the section's vehicles."""

from __future__ import annotations

import math

import pytest
from arzsumo_studies.measures.car_following_stability import lateral_files, predict
from arzsumo_studies.measures.string_stability import IdmParameters, idm_partials, max_string_gain

from arzsumo.model import get_preset
from arzsumo.scenario import scenario_from_dict

PARAMS = get_preset("paper_base").params
#: about the default's stream: 101 HV/km and 22 AV/km at 29 km/h
POINT = (0.101, 0.022, 29 / 3.6)


def _cfg(**sumo):
    return scenario_from_dict({"sumo": sumo}).sumo


@pytest.mark.parametrize(("gap", "files"), [(0.6, 2), (0.15, 3), (0.0, 3), (2.5, 2), (3.0, 1)])
def test_lateral_files_are_the_vehicles_that_fit_side_by_side(gap, files):
    assert lateral_files(gap) == files


def test_sumos_acc_gap_law_is_string_unstable_at_its_default_gains():
    """f_s = 0.23, f_v = -0.23, f_dv = 0.07: f_v^2/2 - f_dv f_v - f_s = -0.187 < 0."""
    pred = predict(PARAMS, _cfg(min_gap_lat_m=0.6), *POINT)["av"]
    assert pred.model == "ACC" and pred.stable is False
    assert pred.vehicles == pytest.approx(22.0)             # the AVs' own, not all 123
    assert pred.growth == pytest.approx(pred.gain ** 22.0)
    assert pred.gain == pytest.approx(1.6974, abs=1e-4)
    # weaker spacing feedback, stronger speed feedback: stable
    calm = predict(PARAMS, _cfg(av_gap_gain_space=0.05, av_gap_gain_speed=2.0), *POINT)["av"]
    assert calm.stable is True and calm.gain == 1.0 and calm.growth == 1.0


def test_idm_is_predicted_at_the_files_net_gap_and_krauss_is_not():
    cfg = _cfg(hv_model="IDM", hv_accel_m_s2=1.0, hv_decel_m_s2=1.5, min_gap_lat_m=0.6)
    pred = predict(PARAMS, cfg, *POINT)["hv"]
    # two files: spacing 2 / 0.123 m, less the mean length (4.8 m HV, 5 m AV)
    gap = 2 / 0.123 - (0.101 * 4.8 + 0.022 * 5.0) / 0.123
    idm = IdmParameters(1.0, 1.5, 1.0, 3.2, 80 / 3.6, 4.0)
    assert pred.gain == pytest.approx(max_string_gain(idm_partials(idm, gap, 29 / 3.6))[0])
    krauss = predict(PARAMS, _cfg(), *POINT)["hv"]
    assert math.isnan(krauss.gain) and krauss.stable is None and "Krauss" in krauss.reason
