"""Plots draw and return Figures and write nothing: no file appears in the working
directory and no figure is saved (saving is :mod:`arzsumo.outputs.figures`' job)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from matplotlib.figure import Figure

import arzsumo.plots
from arzsumo.plots import plt
from arzsumo.plots.alinea import loop_curve_figure
from arzsumo.plots.bridge import bridge_figures
from arzsumo.plots.calibration import calibration_figure
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
