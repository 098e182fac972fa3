"""The run's console line on how often an event-triggered controller updated U."""

import pytest

from arzsumo.bridge.compare import updates_line


@pytest.mark.parametrize("controller", ["etc", "observer-etc"])
def test_an_event_triggered_run_reports_its_updates_and_held_time(controller):
    line = updates_line({"controller": controller, "triggers": 449, "release_time": 1.0,
                         "horizon": 450.0})
    assert line.startswith(f"{controller}: U updated at 449 checks, held unchanged for 1 s "
                           "of the 450 s window")


def test_a_single_update_is_one_check():
    line = updates_line({"controller": "etc", "triggers": 1, "release_time": 449.0,
                         "horizon": 450.0})
    assert line.startswith("etc: U updated at 1 check, held unchanged for 449 s")


@pytest.mark.parametrize("summ", [
    {"controller": "backstepping", "triggers": 450, "release_time": 0.0, "horizon": 450.0},
    {"controller": "open", "triggers": 0, "release_time": 450.0, "horizon": 450.0},
    {"controller": "etc", "horizon": 450.0},          # a twin or older summary: no counts
])
def test_other_runs_get_no_line(summ):
    assert updates_line(summ) is None
