"""The coherence figure draws what it is given: x in m, periods in s, shares as given."""

import numpy as np
import pytest
from arzsumo_studies.measures.coherence import boundary_shares
from arzsumo_studies.plots.coherence import coherence_figure


@pytest.fixture(scope="module")
def results():
    rng = np.random.default_rng(0)
    x = np.arange(25.0, 1000.0, 50.0)                           # m
    b = rng.standard_normal(1800)
    v = 20.0 + b[:, None] + rng.standard_normal((1800, x.size))
    return boundary_shares(v, {"q(0,t)": b, "q(L,t)": rng.standard_normal(1800)}, 1.0,
                           x).results


def test_one_column_per_boundary_with_a_map_and_the_shares(results):
    fig = coherence_figure(results, "open loop")
    maps = [ax for ax in fig.axes if ax.get_title().startswith("coherence with")]
    assert [ax.get_title() for ax in maps] == ["coherence with q(0,t)",
                                               "coherence with q(L,t)"]
    assert len(fig.axes) == 5                                   # 2 x 2 and the colour bar
    top = maps[0]
    assert top.get_yscale() == "log" and top.get_ylabel() == "period (s)"
    res = results["q(0,t)"]
    mesh = top.collections[0]
    np.testing.assert_allclose(mesh.get_array().reshape(-1, res.x.size),
                               res.coherence[:, 1:].T)          # (periods, x), f = 0 left out
    lo, hi = mesh.get_clim()
    assert (lo, hi) == (0.0, 1.0)
    assert sorted({line.get_ydata()[0] for line in top.get_lines()}) == [20.0, 60.0, 600.0]
    bottom = fig.axes[2]
    assert bottom.get_xlabel() == "x (m)"
    lines = bottom.get_lines()
    assert len(lines) == 3                                      # two bands and the floor
    np.testing.assert_allclose(lines[0].get_xdata(), res.x)
    np.testing.assert_allclose(lines[1].get_ydata(), res.share[1])
    np.testing.assert_allclose(lines[2].get_ydata(), res.floor)
    assert lines[0].get_label().startswith("short_waves (20-60 s): 0.")
    assert fig._suptitle.get_text() == "open loop"


def test_no_results_no_figure():
    with pytest.raises(ValueError, match="at least one boundary series"):
        coherence_figure({})
