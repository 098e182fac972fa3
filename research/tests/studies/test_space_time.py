"""``arzsumo study space-time``: its runs are the user's runs of the same scenario and
seed, drawn side by side, reused on a second call; bad options are refused."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.control.space_time import SpaceTimeOptions, run_space_time
from tests.runs import ROOT

from arzsumo.bridge.session import run_in_sumo
from arzsumo.errors import ArzsumoError
from arzsumo.scenario import load_scenario

DEFAULT = ROOT / "scenarios" / "default.toml"
#: a short look: 60 s of warm-up, 20 s of control
TIMES = {"warmup": 60.0, "horizon": 20.0}


@pytest.mark.parametrize(("changes", "field"), [
    ({"controllers": ("open",)}, "controllers"),
    ({"controllers": ("open", "open")}, "controllers"),
    ({"controllers": ("open", "pid")}, "controllers"),
    ({"controllers": ("etc",)}, "controllers"),
    ({"controllers": ("open", "etc", "held", "alinea", "pi-alinea")}, "controllers"),
    ({"experiment": "slowdown"}, "experiment"), ({"seed": -1}, "seed"),
    ({"warmup": -1.0}, "warmup"), ({"horizon": 0.0}, "horizon"),
    ({"horizon": float("nan")}, "horizon"), ({"page": "../control"}, "page")])
def test_options_that_cannot_draw_a_comparison_are_refused(changes, field):
    with pytest.raises(ArzsumoError, match=field):
        SpaceTimeOptions(**changes)


def test_the_controllers_are_drawn_in_the_order_given():
    assert SpaceTimeOptions(controllers=("etc", "open")).controllers == ("etc", "open")
    assert SpaceTimeOptions(controllers=("etc", "held")).controllers == ("etc", "held")


@pytest.mark.sumo
def test_the_runs_are_the_users_runs_drawn_side_by_side_and_reused(tmp_path):
    opts = SpaceTimeOptions(scenario=DEFAULT, seed=3, controllers=("open", "held"),
                            out=tmp_path / "st", docs=tmp_path / "docs", progress=False,
                            **TIMES)
    result = run_space_time(opts)
    assert [p.name for p in result.figures] == [
        "space_time_regulation_seed3_w60_h20_hv.png",
        "space_time_regulation_seed3_w60_h20_av.png"]         # a quick look is named
    assert all(p.stat().st_size > 20_000 for p in result.figures)
    assert (tmp_path / "docs" / "control_default" / result.figures[0].name).is_file()
    page = (tmp_path / "docs" / "control_default.md").read_text(encoding="utf-8")
    assert "space_time_regulation_seed3_w60_h20_av.png" in page
    assert "--controllers open,held --experiment regulation --warmup 60 --horizon 20" in page
    # the study's open loop is `arzsumo run`'s of the same scenario, seed and times
    own = run_in_sumo(load_scenario(DEFAULT), controller="open", seed=3, **TIMES)
    cells = pd.read_parquet(result.runs["open"] / "cells.parquet")
    micro = cells[cells["source"] == "micro"].sort_values(["t_s", "x_m"])
    rho_h = np.asarray(own.result.micro)[:, 0, :].ravel()
    assert np.allclose(micro["rho_h"].to_numpy(), rho_h, equal_nan=True)
    # a second call reuses both runs (nothing of theirs is rewritten)
    stamps = {c: (p / "summary.json").stat().st_mtime_ns for c, p in result.runs.items()}
    again = run_space_time(opts)
    assert {c: (p / "summary.json").stat().st_mtime_ns
            for c, p in again.runs.items()} == stamps
    # another scenario in the same directory is refused, not drawn from the old runs
    other = tmp_path / "other.toml"
    other.write_text(DEFAULT.read_text(encoding="utf-8").replace(
        "horizon_s = 450", "horizon_s = 400", 1), encoding="utf-8")
    with pytest.raises(ArzsumoError, match="another scenario"):
        run_space_time(replace(opts, scenario=other))
