"""The lateral-file table of the control study, on runs whose files are known."""

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.control.files import file_indices, files_per_run, files_table


def _run(controller: str, seed: int, hv: list[tuple[float | None, float | None]],
         av: list[tuple[float | None, float | None]]) -> dict:
    row: dict = {"controller": controller, "seed": seed}
    for cls, files in (("h", hv), ("a", av)):
        for i, (share, speed) in enumerate(files):
            row[f"section.waves.{cls}.files.{i}.share"] = share
            row[f"section.waves.{cls}.files.{i}.speed_mean_kmh"] = speed
    return row


@pytest.fixture
def runs() -> pd.DataFrame:
    return pd.DataFrame([
        # one HV file; AV: a 3 % file at 50 km/h is not a stream and is not counted
        _run("open", 1, [(1.0, 30.0), (None, None)], [(0.97, 28.0), (0.03, 50.0)]),
        # two HV files 12 km/h apart: over the premise's 10 km/h gate
        _run("open", 2, [(0.6, 20.0), (0.4, 32.0)], [(0.5, 27.0), (0.5, 29.5)]),
        _run("etc", 1, [(0.5, 30.0), (0.5, 31.0)], [(1.0, 28.0), (None, None)]),
    ])


def test_indices_come_from_the_columns(runs: pd.DataFrame) -> None:
    assert file_indices(runs, "h") == [0, 1]
    assert file_indices(runs, "a") == [0, 1]


def test_files_and_gaps_per_run(runs: pd.DataFrame) -> None:
    hv = files_per_run(runs, "h")
    assert hv["files"].tolist() == [1, 2, 2]
    np.testing.assert_allclose(hv["gap_kmh"], [0.0, 12.0, 1.0])
    av = files_per_run(runs, "a")
    assert av["files"].tolist() == [1, 2, 1]
    np.testing.assert_allclose(av["gap_kmh"], [0.0, 2.5, 0.0])
    # a lower share counts the sparse file: its 50 km/h opens a 22 km/h gap
    assert files_per_run(runs, "a", min_share=0.01)["gap_kmh"].iloc[0] == pytest.approx(22.0)


def test_the_table_counts_the_runs_over_the_gate(runs: pd.DataFrame) -> None:
    lines = files_table(runs, ["open", "etc", "held"]).splitlines()
    assert "HV runs over 10 km/h" in lines[0]
    assert lines[2] == "| open | 2 | 1.5, 2 | 6.00, 12.00 | 1 | 1.5, 2 | 1.25, 2.50 | 0 |"
    assert lines[3] == "| etc | 1 | 2.0, 2 | 1.00, 1.00 | 0 | 1.0, 1 | 0.00, 0.00 | 0 |"
    assert lines[4] == "| held | 0 |  |  |  |  |  |  |"
