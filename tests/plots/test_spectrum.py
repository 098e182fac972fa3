"""The spectrum figure draws what it is given, in the display units."""

import numpy as np
import pytest

from arzsumo.plots.spectrum import spectrum_figure


def test_one_curve_per_run_and_class_in_kmh_squared_seconds():
    periods = np.array([450.0, 225.0, 150.0])
    psd = np.array([1.0, 2.0, 3.0])                          # (m/s)^2 s
    curves = {"seed4": {"h": (periods, psd), "a": (periods, 2 * psd)},
              "seed5": {"h": (periods, psd), "a": (np.zeros(0), np.zeros(0))}}
    fig = spectrum_figure(curves, {"short": (20.0, 60.0), "long": (60.0, 600.0)}, "t")
    hv, av = fig.axes[:2]
    assert [line.get_label() for line in hv.get_lines()] == ["seed4", "seed5"]
    assert [line.get_label() for line in av.get_lines()] == ["seed4"]   # nothing to draw
    np.testing.assert_allclose(av.get_lines()[0].get_ydata(), 2 * psd * 3.6 ** 2)
    np.testing.assert_allclose(hv.get_lines()[0].get_xdata(), periods)
    spans = list(hv.patches)
    assert len(spans) == 2                                     # the two bands
    assert [s.get_label() for s in spans] == ["short", "long"]
    assert fig._suptitle.get_text() == "t"
    assert hv.get_xscale() == "log" == hv.get_yscale()
    with pytest.raises(KeyError):
        spectrum_figure({"seed6": {"h": (periods, psd)}}, {})   # a class missing
