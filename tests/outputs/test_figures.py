"""The output layer saves the figures of :mod:`arzsumo.plots`: the file names of a run, the
resolution asked for, and every figure closed, also when saving fails; a figure an earlier
call drew is removed when this call draws none, and nothing else."""

from __future__ import annotations

import struct

import numpy as np
import pandas as pd
import pytest

from arzsumo.evaluation.critical_occupancy import critical_occupancy
from arzsumo.outputs.alinea import write_alinea_target
from arzsumo.outputs.evaluation import FIGURE, write_evaluation
from arzsumo.outputs.figures import remove_stale_figures, save_figures, save_png
from arzsumo.plots import plt
from arzsumo.plots.bridge import bridge_figures
from arzsumo.plots.twin import twin_figures
from tests.plots.results import cosim_result, loop_curve_args, twin_run

RUN_PNGS = ["control.png", "fields_a.png", "fields_h.png"]


def _png_size(path) -> tuple[int, int]:
    """(width, height) in pixels from the PNG header."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


@pytest.mark.parametrize(("figures", "result", "dpi", "fields_px"), [
    (twin_figures, twin_run, 110, (1210, 462)),        # 11 x 4.2 in at 110 dpi
    (bridge_figures, cosim_result, 100, (1260, 700)),  # 12.6 x 7 in at 100 dpi
])
def test_a_run_s_figures_get_their_file_names(tmp_path, figures, result, dpi, fields_px):
    figs = figures(result())
    paths = save_figures(figs, tmp_path, dpi=dpi)
    assert [p.name for p in paths] == ["fields_h.png", "fields_a.png", "control.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == RUN_PNGS
    assert _png_size(tmp_path / "fields_h.png") == fields_px
    assert not set(plt.get_fignums()) & {f.number for f in figs.values()}


def test_a_failed_save_closes_every_figure_and_leaves_no_part(tmp_path):
    figs = twin_figures(twin_run())

    def broken(*args, **kwargs):
        raise RuntimeError("disk full")

    figs["fields_a"].savefig = broken                  # the second of three fails
    with pytest.raises(RuntimeError, match="disk full"):
        save_figures(figs, tmp_path)
    assert not set(plt.get_fignums()) & {f.number for f in figs.values()}
    assert [p.name for p in tmp_path.iterdir()] == ["fields_h.png"]    # no temporary left


def test_save_png_writes_the_path_and_closes(tmp_path):
    from arzsumo.plots.calibration import loop_curve_figure

    fig = loop_curve_figure(*loop_curve_args())
    assert save_png(fig, tmp_path / "curve.png", dpi=50) == tmp_path / "curve.png"
    assert _png_size(tmp_path / "curve.png") == (350, 230)     # 7 x 4.6 in at 50 dpi
    assert fig.number not in plt.get_fignums()


def test_alinea_target_writes_its_four_files(tmp_path):
    rng = np.random.default_rng(4)
    occ = rng.uniform(0.02, 0.6, 300)
    flow = np.where(occ < 0.22, 0.55 * occ / 0.22, 0.55 * (0.8 - occ) / 0.58)
    crit = critical_occupancy(occ, flow)
    out = write_alinea_target(tmp_path / "t", [(1, occ, flow)], crit, {"seeds": [1]}, "t")
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "curve.csv", "curve.png", "samples.csv", "target.json"]
    assert _png_size(out / "curve.png") == (770, 506)          # 7 x 4.6 in at 110 dpi


def test_only_a_regular_file_is_removed_as_a_stale_figure(tmp_path):
    figure, folder, link = tmp_path / "map.png", tmp_path / "shift.png", tmp_path / "u.png"
    figure.write_bytes(b"png")
    folder.mkdir()
    theirs = tmp_path / "elsewhere.png"
    theirs.write_bytes(b"the user's")
    link.symlink_to(theirs)
    assert remove_stale_figures(figure, folder, link, tmp_path / "none.png") == [figure]
    assert not figure.exists() and folder.is_dir() and link.is_symlink()
    assert theirs.read_bytes() == b"the user's"


def test_an_evaluation_written_without_plots_drops_its_earlier_figure(tmp_path):
    (tmp_path / FIGURE).write_bytes(b"an earlier call's")
    long = pd.DataFrame(columns=["measure", "controller"])
    written = write_evaluation(tmp_path, long, pd.DataFrame(), ["open", "etc"], "# head",
                               plots=False)
    assert [p.name for p in written] == ["evaluation.csv", "evaluation.md"]
    assert not (tmp_path / FIGURE).exists()
