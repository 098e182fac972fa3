"""The sweep engine as a batch runner (:func:`arzsumo.sweep.driver.map_runs`): the order of
the results is the order of the tasks, in this process or on the pool; a task that kills
its process twice raises."""

from __future__ import annotations

import os

import pytest

from arzsumo.sweep.driver import map_runs


def test_results_come_back_in_task_order_on_the_pool_and_here():
    tasks = [-5, 3, -1, 0, 7, -2]
    assert map_runs(abs, tasks, workers=2) == [5, 3, 1, 0, 7, 2]
    assert map_runs(abs, tasks, in_process=True) == [5, 3, 1, 0, 7, 2]
    assert map_runs(abs, [], workers=2) == []


def test_a_task_that_kills_its_process_twice_raises():
    with pytest.raises(RuntimeError, match="worker process died"):
        map_runs(os._exit, [3], workers=1)


def test_a_labelled_batch_reports_its_progress_and_an_unlabelled_one_is_silent(capsys):
    assert map_runs(abs, [-1, -2, -3], workers=1, progress="batch") == [1, 2, 3]
    err = capsys.readouterr().err
    assert "batch [" in err and "100.0%" in err
    assert map_runs(abs, [-1, -2, -3], workers=1) == [1, 2, 3]
    assert capsys.readouterr().err == ""
