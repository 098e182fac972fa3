"""The run's progress: time left over phases of unequal cost, on a fake clock."""

from __future__ import annotations

import io

import pytest

from arzsumo.bridge.run_progress import run_phases
from arzsumo.progress import Phase, PhaseClock, RunProgress, duration_text


class FakeClock:
    """A clock that moves only when told."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def walk(timer: PhaseClock, clock: FakeClock, start: float, stop: float,
         seconds_per_unit: float, step: float = 1.0) -> None:
    """Do units ``start``..``stop`` of the current phase at ``seconds_per_unit``."""
    done = start
    while done < stop - 1e-9:
        done = min(stop, done + step)
        clock.now += step * seconds_per_unit
        timer.update(done)


def test_rest_of_phase_at_its_own_rate_and_later_phases_by_cost() -> None:
    # A: 100 units at 1 s each; B costs twice A: 200 s at A's rate
    clock = FakeClock()
    timer = PhaseClock([Phase("A", 100, 100), Phase("B", 100, 200)], clock)
    walk(timer, clock, 0, 50, 1.0)
    assert timer.seconds_left() == pytest.approx(50 + 200)
    assert timer.fraction() == pytest.approx(50 / 300)


def test_a_cheap_start_gives_no_rate_until_the_phase_settles() -> None:
    # the first 20 units step ten times faster than the rest (a network filling)
    clock = FakeClock()
    timer = PhaseClock([Phase("warm-up", 100, 100, settle=0.2), Phase("control", 100, 150)],
                       clock)
    walk(timer, clock, 0, 20 - 1, 0.1)
    assert timer.seconds_left() is None          # nothing representative measured yet
    walk(timer, clock, 19, 20, 0.1)
    walk(timer, clock, 20, 60, 1.0)
    # 40 units left at 1 s, control 150 cost units at 1 s each; an estimate from the
    # mean rate since t = 0 (42 s for 60 units) would say 28 + 105 s
    assert timer.seconds_left() == pytest.approx(40 + 150)


def test_the_rate_follows_the_last_window_when_the_machine_slows() -> None:
    clock = FakeClock()
    timer = PhaseClock([Phase("A", 200, 200), Phase("B", 1, 100)], clock, window=20.0)
    walk(timer, clock, 0, 100, 1.0)
    walk(timer, clock, 100, 150, 2.0)   # another job takes half the machine
    # the last 20 s saw 10 units: 2 s per unit for A's 50 units and B's 100 cost units
    assert timer.seconds_left() == pytest.approx(2 * 50 + 2 * 100)


def test_later_phases_use_the_finished_phases_rate() -> None:
    clock = FakeClock()
    timer = PhaseClock([Phase("sim", 100, 100), Phase("drain", 10, 50),
                        Phase("writing", 1, 20)], clock)
    walk(timer, clock, 0, 100, 0.5)     # 0.5 s per unit of cost
    timer.enter("drain", work=400)      # vehicles in the network, known at its start
    assert timer.phase.work == 400
    assert timer.seconds_left() == pytest.approx(0.5 * (50 + 20))
    walk(timer, clock, 0, 100, 0.1, step=10)   # its own rate: 0.1 s a vehicle
    # 300 vehicles left at 0.1 s; the drain's 400 vehicles at that rate, 40 s for its
    # 50 units of cost, price the writing's 20 units at 0.8 s each
    assert timer.seconds_left() == pytest.approx(300 * 0.1 + 20 * 0.8)
    clock.now += 30.0
    timer.enter("writing")
    assert timer.durations["drain"] == pytest.approx(40.0)
    # a single step has no rate of its own: its expected cost, less the time it has run
    expected = 20 * (40.0 / 50)          # the drain's 40 s for its 50 units of cost
    assert timer.seconds_left() == pytest.approx(expected)
    clock.now += 5.0
    assert timer.seconds_left() == pytest.approx(expected - 5.0)
    clock.now += 100.0
    assert timer.seconds_left() == 0.0


def test_an_offset_counts_the_phase_from_its_own_start() -> None:
    clock = FakeClock()
    timer = PhaseClock([Phase("warm-up", 600, 600), Phase("control", 450, 900)], clock)
    walk(timer, clock, 0, 600, 0.1, step=10)
    timer.enter("control", offset=600.0)
    timer.update(600 + 45)                 # the loop gives SUMO's time
    assert timer.done == 45
    assert timer.fraction() == pytest.approx((600 + 90) / 1500)


@pytest.mark.parametrize(("phases", "name", "match"), [
    ([Phase("A"), Phase("B")], "C", "not ahead"),
    ([], None, "at least one phase"),
])
def test_refusals(phases: list[Phase], name: str | None, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        PhaseClock(phases, FakeClock()).enter(name or "A")


def test_a_phase_checks_itself() -> None:
    with pytest.raises(ValueError, match="settle = 1"):
        Phase("A", 1, 1, settle=1.0)


def test_the_bar_names_the_phase_and_ends_with_each_phases_time() -> None:
    clock, out = FakeClock(), io.StringIO()
    bar = RunProgress(run_phases(600, 450, 1800, writing=True), "etc seed 42", stream=out,
                      clock=clock)
    with bar:
        walk(bar.timer, clock, 0, 600, 0.1, step=10)
        bar.update(600)
        bar.enter("control", offset=600)
        for t in range(601, 1051):
            clock.now += 0.2
            bar.update(t)
        bar.enter("drain", work=300)
        bar.update(150)
        bar.enter("measures")
        bar.enter("writing results")
        clock.now += 10
    lines = out.getvalue().splitlines()
    assert all(len(line) <= 100 for line in lines)
    assert any("control" in line and "/450 s" in line for line in lines)
    assert any("drain 0/300 veh out" in line for line in lines)
    assert any("writing results" in line for line in lines)
    end = out.getvalue()[out.getvalue().index("etc seed 42 took"):]
    assert " ".join(end.split()) == ("etc seed 42 took 2 min 40 s: warm-up 60 s, control 90 s, "
                                     "drain 0 s, measures 0 s, writing results 10 s")


def test_the_run_phases_follow_the_options() -> None:
    names = [p.name for p in run_phases(600, 450, 0)]
    assert names == ["warm-up", "control", "measures"]
    assert [p.name for p in run_phases(600, 450, 1800, writing=True)][2:] == [
        "drain", "measures", "writing results"]


@pytest.mark.parametrize(("seconds", "text"), [
    (4.4, "4 s"), (65, "1 min 05 s"), (3725, "1 h 02 min"), (-3, "0 s")])
def test_duration_text(seconds: float, text: str) -> None:
    assert duration_text(seconds) == text
