"""The paired figure's title names the seeds its dots stand on."""

import pandas as pd

from arzsumo.outputs.evaluation import paired_title


def _runs(counts: dict[str, int]) -> pd.DataFrame:
    return pd.DataFrame([{"controller": c, "seed": s}
                         for c, n in counts.items() for s in range(1, n + 1)])


def test_controllers_at_different_seed_counts_name_the_range() -> None:
    runs = _runs({"open": 20, "alinea": 10, "backstepping": 20, "held": 12})
    title = paired_title(runs, ["open", "alinea", "backstepping", "held"], "open")
    assert "(10-20 seeds)" in title
    assert title.startswith("minus open, same seed")


def test_one_count_is_named_once() -> None:
    runs = _runs({"open": 20, "etc": 7, "backstepping": 7})
    assert "(7 seeds)" in paired_title(runs, ["open", "etc", "backstepping"], "open")
