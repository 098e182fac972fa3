"""Plots draw and return Figures and write nothing: no file appears in the working
directory and no figure is saved (saving is :mod:`arzsumo.outputs.figures`' job)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from matplotlib.figure import Figure

import arzsumo.plots
from arzsumo.plots import plt
from arzsumo.plots.bridge import bridge_figures
from arzsumo.plots.calibration import calibration_figure, loop_curve_figure
from arzsumo.plots.twin import twin_figures
from tests.plots.results import calibration_args, cosim_result, loop_curve_args, twin_run

RUN_FIGURES = ["fields_h", "fields_a", "control"]


@pytest.fixture
def no_saving(tmp_path, monkeypatch):
    """Run in an empty working directory and record every ``Figure.savefig`` call."""
    monkeypatch.chdir(tmp_path)
    calls: list[object] = []
    monkeypatch.setattr(Figure, "savefig", lambda self, *a, **k: calls.append(a))
    yield calls
    assert list(tmp_path.iterdir()) == []
    plt.close("all")


def test_bridge_figures_are_returned_by_name(no_saving):
    figs = bridge_figures(cosim_result())
    assert list(figs) == RUN_FIGURES
    assert all(isinstance(f, Figure) for f in figs.values())
    assert len(figs["fields_h"].axes) == 2 * 3 + 2       # 2 rows x 3 sources, 2 colour bars
    assert len(figs["control"].axes) == 4
    assert figs["control"].get_suptitle() == "s: etc, seed 1"
    assert no_saving == []


def test_twin_figures_are_returned_by_name(no_saving):
    figs = twin_figures(twin_run(complete=False))
    assert list(figs) == RUN_FIGURES
    assert len(figs["fields_a"].axes) == 2 + 2           # density, speed, their colour bars
    assert len(figs["control"].axes) == 3                # U, events, the deviation norm
    assert figs["fields_h"].get_suptitle() == "tw, etc (INCOMPLETE)"
    assert no_saving == []


@pytest.mark.parametrize(("draw", "args", "axes"), [
    (loop_curve_figure, loop_curve_args(), 1),
    (calibration_figure, calibration_args(), 3),
])
def test_single_figures_are_returned(no_saving, draw, args, axes):
    fig = draw(*args)
    assert isinstance(fig, Figure) and len(fig.axes) == axes
    assert no_saving == []


def test_no_plots_module_saves_or_opens_files():
    """No plots module calls ``savefig``/``open``/``write_*`` or defines a writer."""
    found = []
    for path in Path(arzsumo.plots.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef) and node.name.startswith(("write", "save")):
                found.append(f"{path.name}: def {node.name}")
            if isinstance(node, ast.Call):
                name = getattr(node.func, "attr", getattr(node.func, "id", ""))
                if name in ("savefig", "open", "write_text", "write_bytes", "mkdir"):
                    found.append(f"{path.name}:{node.lineno}: {name}()")
    assert found == []


def test_the_fields_tell_waves_from_vehicles_and_label_the_equilibrium(no_saving):
    figs = bridge_figures(cosim_result(), {"h": -35.0, "a": float("nan")})
    fields_h, fields_a = figs["fields_h"], figs["fields_a"]
    (legend,) = fields_h.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert texts[0] == "waves (speed fluctuations), measured: -35 km/h, upstream"
    assert texts[1].startswith("vehicles' mean speed: +")
    assert texts[1].endswith("km/h, downstream; stripes along it move with the vehicles "
                             "(groups and gaps), not waves")
    # a wave line and a vehicles' line on each of the 6 panels
    assert sum(len(ax.lines) for ax in fields_h.axes[:6]) == 12
    bars = [ax.get_ylabel() for ax in fields_h.axes[6:]]
    assert bars == ["veh/km; dashed: equilibrium 30", "km/h; dashed: equilibrium 72"]
    (legend_a,) = fields_a.legends
    assert legend_a.get_title().get_text() == ("waves (speed fluctuations), measured: no "
                                               "travel speed resolved")
    assert [t.get_text()[:20] for t in legend_a.get_texts()] == ["vehicles' mean speed"]


def test_without_measured_waves_no_guides_are_drawn(no_saving):
    fields = bridge_figures(cosim_result())["fields_h"]
    assert fields.legends == [] and all(len(ax.lines) == 0 for ax in fields.axes[:6])
