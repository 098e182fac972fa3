"""``arzsumo compare``: repeated over a glob that holds its own output, the table's leading
measures and units, and a figure that draws only measures >= 0 (no SUMO)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from arzsumo.bridge.compare import COLUMNS, summary_table
from arzsumo.cli import main


def _summary(controller: str, seed: int, delay_s: float) -> dict:
    return {"kind": "run", "scenario": "s", "horizon": 60.0, "warmup": {"duration_s": 600.0},
            "controller": controller, "seed": seed, "plan_changes": 3, "light_changes": 8,
            "triggers": 3, "release_time": 40.0, "TTT": {"total": 7200.0},
            "total_delay": {"total": delay_s}, "J_fuel": {"total": 12.0},
            "J_discom": {"total": 5.0}, "speed_variance": {"h": 4.0, "a": 1.0},
            "max_ramp_queue": 4, "network": {"time_loss_s": {"total": 1800.0}},
            "network_whole_demand": {"complete": True, "time_spent_s": {"total": 36000.0},
                                     "ramp_wait_s": {"p95": 95.0}}}


def _run(path, controller: str, seed: int, delay_s: float = -360.0):
    path.mkdir(parents=True)
    (path / "summary.json").write_text(json.dumps(_summary(controller, seed, delay_s)))
    return path


def _glob(root) -> list[str]:
    """``results/*/`` as the shell expands it."""
    return sorted(f"{p}/" for p in root.iterdir() if p.is_dir())


def test_compare_over_a_glob_that_holds_its_own_output(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    _run(tmp_path / "results" / "a", "etc", 1)
    _run(tmp_path / "results" / "b", "open", 1)
    out = "results/comparison"
    assert main(["compare", *_glob(tmp_path / "results"), "--out", out]) == 0
    first = capsys.readouterr()
    assert first.err == ""
    # the glob now matches the comparison's own directory
    assert main(["compare", *_glob(tmp_path / "results"), "--out", out]) == 0
    again = capsys.readouterr()
    assert again.err == (f"arzsumo: note: skipped {tmp_path / 'results' / 'comparison'}: "
                         "the --out directory of this comparison\n")
    assert again.out == first.out
    assert pd.read_csv(tmp_path / out / "comparison.csv")["controller"].tolist() == ["etc",
                                                                                     "open"]
    # another comparison's output among the runs is skipped too
    assert main(["compare", *_glob(tmp_path / "results"), "--out", "results/second"]) == 0
    err = capsys.readouterr().err
    assert "skipped " in err and "the output of an earlier arzsumo compare, not a run" in err
    assert main(["compare", "results/comparison", "--out", "results/comparison"]) == 2
    assert "no run directory left to compare" in capsys.readouterr().err


def test_the_table_leads_with_the_judged_measures_each_with_its_unit():
    text = summary_table([_summary("etc", 1, 360.0), _summary("open", 1, 720.0)])
    header = text.splitlines()[1].split("  ")
    heads = [h.strip() for h in header if h.strip()]
    assert heads[:5] == ["controller", "seed", "whole TTS veh.h", "ramp wait p95 s",
                         "time loss veh.h"]
    row = text.splitlines()[2].split()
    assert row[:5] == ["etc", "1", "10", "95", "0.5"]            # 36000 s, 95 s, 1800 s
    units = ("veh.h", " s", "km/h", " n", " veh", " SI", " %")
    measures = [h for c, h in COLUMNS if c not in ("scenario", "controller", "seed", "kind")]
    assert all(h.endswith(units) for h in measures), measures
    assert "J_discom SI: veh m^2/s^3 + veh m^2/s^5" in " ".join(text.split())


def test_the_figure_draws_no_negative_delay(tmp_path, monkeypatch):
    import arzsumo.outputs.figures as plots
    from arzsumo.outputs.compare import compare_runs

    figures = []
    save = plots.save_png
    monkeypatch.setattr(plots, "save_png", lambda fig, *a, **k: (figures.append(fig),
                                                                 save(fig, *a, **k))[1])
    runs = [_run(tmp_path / "a", "etc", 1, -360.0), _run(tmp_path / "b", "open", 1, -720.0)]
    compare_runs(runs, tmp_path / "out")
    (fig,) = figures
    titles = [ax.get_title() for ax in fig.axes]
    assert titles[:3] == ["whole-demand TTS (veh h)", "ramp wait, 95th percentile (s)",
                          "network time loss (veh h)"]
    assert not any("delay" in t for t in titles)
    heights = np.array([b.get_height() for ax in fig.axes for b in ax.patches])
    assert heights.size == 2 * len(titles) and (heights >= 0).all()
    assert sorted(heights[:2]) == pytest.approx([10.0, 10.0])


def test_compare_never_writes_into_a_run_or_a_user_directory(tmp_path, capsys):
    a, b = _run(tmp_path / "a", "etc", 1), _run(tmp_path / "b", "open", 1)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "comparison.csv").write_text("mine\n")
    for out in (a, mine):       # a run's results, a directory of the user's
        assert main(["compare", str(a), str(b), "--out", str(out)]) == 2
        assert "allowed: a new or empty directory" in capsys.readouterr().err
    assert (mine / "comparison.csv").read_text() == "mine\n"
    assert sorted(p.name for p in a.iterdir()) == ["summary.json"]
    out = tmp_path / "cmp"
    assert main(["compare", str(a), str(b), "--out", str(out)]) == 0
    assert main(["compare", str(a), str(b), "--out", str(out)]) == 0   # its own: rewritten


def test_the_default_out_is_under_results_and_the_table_explains_its_counts(tmp_path):
    """Without --out the comparison goes to results/comparison (not the working directory's
    top level), and the legend under the table says what plan, light and update counts are."""
    from arzsumo.bridge.compare import LEGEND
    from arzsumo.cli import build_parser

    args = build_parser().parse_args(["compare", str(tmp_path)])
    assert args.out == "results/comparison"
    for words in ("plan chg:", "light chg:", "updates:"):
        assert words in LEGEND
