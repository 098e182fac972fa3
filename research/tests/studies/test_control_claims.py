"""The section-5 claims read from a control study's runs: verdicts from paired intervals."""

from __future__ import annotations

import pandas as pd
from arzsumo_studies.control.claims import claims, claims_table

SEEDS = [1, 2, 3, 4, 5]


def runs(decayed_open: bool = True) -> pd.DataFrame:
    rows = []
    base = {"open": (100.0, 0, 0, 50.0, 200.0), "backstepping": (100.0, 450, 300, 40.0, 150.0),
            "etc": (100.0, 90, 60, 45.0, 120.0), "observer-etc": (101.0, 200, 150, 48.0, 160.0)}
    for c, (tts_h, triggers, plans, discom, decay) in base.items():
        for s in SEEDS:
            wobble = 0.1 * (s - 3)          # the same on every controller: paired away
            rows.append({"controller": c, "seed": s,
                         "network_whole_demand.time_spent_s.total": 3600 * (tts_h + wobble
                                                                            + 0.01 * s),
                         "triggers": triggers + s, "plan_changes": plans + s,
                         "section.J_discom.total": discom + wobble,
                         "section.deviation.decay_time_s": decay + 10 * s,
                         "section.deviation.decayed": decayed_open if c == "open" else True})
    return pd.DataFrame(rows)


def test_the_verdicts_follow_the_intervals():
    got = {c.claim: c for c in claims(runs(), SEEDS)}
    fewer = got["ETC close to backstepping with far fewer updates"]
    assert fewer.verdict == "yes" and "ETC / backstepping = 0.21" in fewer.measured
    settle = got["open loop does not settle, ETC stabilises"]
    assert settle.verdict == "no: the open loop settles" and "100%" in settle.measured
    assert got["observer-ETC triggers more than ETC"].verdict == "yes"
    # ETC's J_discom is 5 above backstepping's on every seed
    assert got["ETC less comfortable than backstepping (J_discom)"].verdict == "yes"


def test_an_open_loop_that_does_not_settle_asks_whether_etc_decays_faster():
    got = {c.claim: c for c in claims(runs(decayed_open=False), SEEDS)}
    # ETC's decay time is 80 s shorter than the open loop's on every seed
    assert got["open loop does not settle, ETC stabilises"].verdict == "yes"


def test_missing_controllers_give_no_verdict():
    only = runs()[lambda r: r["controller"] != "observer-etc"]
    got = {c.claim: c for c in claims(only, SEEDS)}
    assert got["observer-ETC triggers more than ETC"].verdict == "n/a"
    table = claims_table({"regulation": only}, SEEDS)
    assert table.splitlines()[0] == "| claim (paper) | SUMO, regulation |"
    assert claims_table({"regulation": only[only["controller"] == "open"]}, SEEDS) == ""
