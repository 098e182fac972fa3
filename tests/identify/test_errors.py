"""Bad inputs raise IdentifyError (an ArzsumoError) with a one-line message."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.errors import ArzsumoError
from arzsumo.identify import (
    FitSettings,
    IdentifyError,
    ReplayData,
    ReplayOptions,
    identify,
    replay,
    validate,
)

T, N = 4, 5


def _arrays(**change):
    star = np.array([0.1, 8.0, 0.05, 7.0])
    args = {"t": np.arange(1, T + 1) * 2.0, "x": np.arange(N) * 200.0 + 100.0,
            "fields": np.broadcast_to(star[None, :, None], (T, 4, N)).copy(),
            "initial": np.broadcast_to(star[:, None], (4, N)).copy(),
            "inlet": np.broadcast_to(star, (T, 4)).copy(), "outflow": np.full(T, 1.0)}
    args.update(change)
    return args


def _nan_fields():
    f = _arrays()["fields"]
    f[:, 1] = np.nan
    return f


@pytest.mark.parametrize(("change", "match"), [
    ({"fields": np.full((T, 4, N), np.nan)}, "all NaN"),
    ({"fields": _nan_fields()}, "fields of v_h are all NaN"),
    ({"fields": np.ones((T, 4, N + 1))}, r"fields has shape \(4, 4, 6\); expected \(4, 4, 5\)"),
    ({"inlet": np.ones((T + 1, 4))}, r"inlet has shape"),
    ({"outflow": np.ones(T - 1)}, r"outflow has shape \(3,\); expected \(4,\)"),
    ({"initial": np.full((4, N), np.nan)}, r"initial\[0, 0\] = nan is not allowed"),
    ({"t": np.array([2.0, 1.0, 3.0, 4.0])}, "strictly increasing"),
    ({"x": np.array([0.0, 1.0, 1.0, 2.0, 3.0])}, "strictly increasing positions"),
    ({"outflow": np.full(T, -1.0)}, "outflow = -1.0 veh/s"),
    ({"initial": np.zeros((4, N))}, "densities > 0"),
    ({"fields": "abc"}, "numbers expected"),
])
def test_bad_data(change, match):
    with pytest.raises(IdentifyError, match=match) as info:
        ReplayData.from_arrays(**_arrays(**change), name="seed 3")
    assert "\n" not in str(info.value) and str(info.value).startswith("seed 3: ")
    assert isinstance(info.value, ArzsumoError)


@pytest.fixture
def data():
    return ReplayData.from_arrays(**_arrays())


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"bounds": {"tau_h": (40.0, 90.0)}}, r"initial guess tau_h = 20 is outside its bounds "
                                          r"\[40, 90\]"),
    ({"bounds": {"tau_h": (5.0, 1.0)}}, "0 < lower < upper"),
    ({"which": ("ao_max_h",), "bounds": {"ao_max_h": (0.5, 1.2)}}, "at most 1"),
    ({"bounds": {"gamma_h": (1.0, 3.0)}}, r"bounds for \['gamma_h'\] are not allowed"),
    ({"which": ("tau_h", "road_width")}, r"which = \['road_width'\] is not allowed"),
    ({"which": ()}, "distinct names"),
    ({"weights": (1.0, 1.0, 1.0)}, "4 numbers >= 0"),
    ({"weights": (0.0, 0.0, 0.0, 0.0)}, "not all 0"),
    ({"penalty": -1.0}, "penalty = -1.0 is not allowed"),
    ({"settings_max_nfev": 0}, "max_nfev = 0 is not allowed"),
])
def test_bad_fit_arguments(data, truth, kwargs, match):
    kwargs = dict(kwargs)
    which = kwargs.pop("which", ("tau_h",))
    with pytest.raises(IdentifyError, match=match) as info:
        if "settings_max_nfev" in kwargs:
            FitSettings(max_nfev=kwargs.pop("settings_max_nfev"))
        identify([data], truth.with_(tau_h=20.0), which=which, **kwargs)
    assert "\n" not in str(info.value)


def test_bad_datasets_and_options(data, truth):
    with pytest.raises(IdentifyError, match="one or more ReplayData"):
        identify([], truth)
    with pytest.raises(IdentifyError, match="one or more ReplayData"):
        validate(truth, [np.zeros(3)])
    with pytest.raises(IdentifyError, match=r"ao_limit = 1\.5 is not allowed"):
        ReplayOptions(ao_limit=1.5)
    with pytest.raises(ArzsumoError, match="cells = 2 is not allowed"):
        ReplayOptions(cells=2)
    far = ReplayData.from_arrays(**_arrays(x=np.arange(N) * 400.0 + 100.0))
    with pytest.raises(IdentifyError, match=r"x reaches 1700.0 m, beyond the road length"):
        replay(truth, far)
