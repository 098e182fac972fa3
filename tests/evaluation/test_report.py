"""The evaluation table on known per-seed data (no SUMO)."""

import math

import numpy as np
import pandas as pd
import pytest

from arzsumo.evaluation.report import (
    COLUMNS,
    MEASURES,
    Measure,
    evaluate,
    markdown,
    paired_differences,
)
from arzsumo.evaluation.stats import StatisticsError

DELAY = Measure("network.time_loss_s.total", "time loss", "veh h", 1 / 3600)
FLOW = Measure("network.throughput_veh_h.section_outlet", "outlet", "veh/h",
               lower_is_better=False)


def _runs(shift_s: float = -360.0, flow_shift: float = 60.0) -> pd.DataFrame:
    rng = np.random.default_rng(1)
    base = rng.normal(7200.0, 900.0, 5)
    flow = rng.normal(4000.0, 200.0, 5)
    rows = []
    for seed, (b, f) in enumerate(zip(base, flow, strict=True), start=1):
        rows.append({"controller": "open", "seed": seed, DELAY.key: b, FLOW.key: f})
        rows.append({"controller": "alinea", "seed": seed, DELAY.key: b + shift_s,
                     FLOW.key: f + flow_shift})
    return pd.DataFrame(rows)


def test_a_constant_shift_is_recovered_with_a_zero_width_interval():
    long = evaluate(_runs(), ["open", "alinea"], measures=[DELAY, FLOW])
    assert list(long.columns) == list(COLUMNS)
    row = long[(long.measure == DELAY.key) & (long.controller == "alinea")].iloc[0]
    assert row.diff_mean == pytest.approx(-0.1)          # -360 s = -0.1 veh h
    assert row.diff_ci_low == pytest.approx(-0.1) and row.diff_ci_high == pytest.approx(-0.1)
    assert row.diff_boot_low == pytest.approx(-0.1)
    assert (row.wins, row.losses, row.ties, row.n) == (5, 0, 0, 5)
    flow = long[(long.measure == FLOW.key) & (long.controller == "alinea")].iloc[0]
    assert flow.diff_mean == pytest.approx(60.0) and flow.wins == 5   # higher is better


def test_the_baseline_against_itself_is_zero_with_zero_width():
    long = evaluate(_runs(), ["open", "alinea"], measures=[DELAY])
    row = long[long.controller == "open"].iloc[0]
    assert row.diff_mean == 0.0 and row.diff_ci_low == 0.0 and row.diff_ci_high == 0.0
    assert (row.wins, row.losses, row.ties) == (0, 0, 5)
    runs = _runs()
    open_h = runs[runs.controller == "open"][DELAY.key] / 3600
    assert row["mean"] == pytest.approx(open_h.mean())
    assert row.ci_low < row["mean"] < row.ci_high


def test_a_missing_run_drops_its_pair_only():
    runs = _runs(shift_s=float("nan"))
    runs.loc[(runs.controller == "alinea") & (runs.seed != 2), DELAY.key] = \
        runs.loc[(runs.controller == "open") & (runs.seed != 2), DELAY.key].to_numpy() + 36.0
    long = evaluate(runs, ["open", "alinea"], measures=[DELAY])
    row = long[long.controller == "alinea"].iloc[0]
    assert row.n == 4 and row.diff_mean == pytest.approx(0.01)
    assert paired_differences(runs, DELAY, ["open", "alinea"])["alinea"].size == 4
    # a measure no run has: n = 0 and NaN, not an error
    gone = evaluate(runs, ["open", "alinea"], measures=[Measure("nope", "none", "1")])
    assert (gone.n == 0).all() and gone["mean"].isna().all()


def test_the_baseline_must_be_evaluated():
    with pytest.raises(StatisticsError, match="baseline = 'open' is not among"):
        evaluate(_runs(), ["alinea"])


def test_markdown_lists_every_measure_and_controller():
    long = evaluate(_runs(), ["open", "alinea"])
    text = markdown(long)
    assert text.count("\n") == 1 + 2 * len(MEASURES)
    assert "| time loss" not in text          # only the default measures
    assert "window time loss, total (lower is better) | veh h | alinea | 5 |" in text
    assert "-0.1 [-0.1, -0.1] | 5 / 0 / 0 |" in text
    assert all(math.isnan(v) for v in long[long.measure == "plan_changes"]["mean"])


def test_a_renamed_key_reads_its_former_name_in_older_runs():
    """``section.speed_spread_kmh`` was ``section.speed_sd_kmh``: a baseline borrowed from
    runs made before the rename still pairs with the new runs."""
    spread = next(m for m in MEASURES if m.key == "section.speed_spread_kmh.h")
    assert spread.aliases == ("section.speed_sd_kmh.h",)
    runs = pd.DataFrame([
        {"controller": "open", "seed": 1, "section.speed_sd_kmh.h": 20.0},
        {"controller": "open", "seed": 2, "section.speed_sd_kmh.h": 22.0},
        {"controller": "alinea", "seed": 1, "section.speed_spread_kmh.h": 18.0},
        {"controller": "alinea", "seed": 2, "section.speed_spread_kmh.h": 21.0}])
    row = evaluate(runs, ["open", "alinea"], measures=[spread]).iloc[1]
    assert row.n == 2 and row.diff_mean == pytest.approx(-1.5) and row.wins == 2
    keys = {m.key for m in MEASURES}
    assert {"section.waves.h.band_power_kmh2", "section.waves.a.growth_per_km"} <= keys


def test_a_run_whose_drain_did_not_empty_the_network_has_no_whole_demand_value():
    from arzsumo.evaluation.report import per_seed

    whole = next(m for m in MEASURES if m.key == "network_whole_demand.time_spent_s.total")
    rows = [{"controller": c, "seed": s, whole.key: 3600.0 * (100 + s + (c == "etc")),
             "network_whole_demand.complete": not (c == "etc" and s == 2)}
            for c in ("open", "etc") for s in (1, 2, 3)]
    wide = per_seed(pd.DataFrame(rows), whole, ["open", "etc"])
    assert wide.loc[2, "etc"] != wide.loc[2, "etc"]          # NaN: a gridlocked drain
    assert list(wide["open"]) == [101.0, 102.0, 103.0] and wide.loc[3, "etc"] == 104.0
    long = evaluate(pd.DataFrame(rows), ["open", "etc"], measures=[whole])
    etc = long[long.controller == "etc"].iloc[0]
    assert etc["n"] == 2 and etc["diff_mean"] == pytest.approx(1.0)
