import numpy as np

from arzsumo.model import ModelParameters, characteristic_speeds
from arzsumo.model.regime import regime_map


def test_regime_map_has_both_regimes_and_matches_pointwise():
    p = ModelParameters()
    rmap = regime_map(p, n=60)
    congested = np.nan_to_num(rmap.lambda_4, nan=np.inf) < 0
    assert congested.any() and (~congested & np.isfinite(rmap.lambda_4)).any()
    i, j = 20, 30
    lam = characteristic_speeds(p, rmap.rho_h[j], rmap.rho_a[i])
    assert lam[3] == rmap.lambda_4[i, j]


def test_light_traffic_is_free_and_dense_traffic_congested():
    p = ModelParameters()
    assert characteristic_speeds(p, 0.01, 0.01)[3] > 0
    assert characteristic_speeds(p, 0.11, 0.095)[3] < 0
