"""MeterGain: a law in outflow units on a meter of gain g asks for U / g and hears g x."""

import math

import numpy as np
import pytest

from arzsumo.control.base import Applied, Controller, MacroState
from arzsumo.control.meter_gain import MeterGain
from arzsumo.errors import ModelError


class Told(Controller):
    """U = 0.3 veh/s at every check, an event every other check; records what it is told."""

    name = "told"

    def reset(self) -> None:
        super().reset()
        self.calls: list[tuple[str, tuple[float, ...]]] = []

    def decide(self, state: MacroState) -> float:
        self.log.record(state.t, 0.3, 0.4, len(self.log.t) % 2 == 0, V=1.5)
        return 0.3

    def applied(self, u, lower=-math.inf, upper=math.inf):
        self.calls.append(("applied", (u, lower, upper)))

    def actuated(self, u):
        self.calls.append(("actuated", (u,)))

    def set_output_noise(self, sd):
        self.calls.append(("noise", (sd,)))
        return True


def _state(t: float) -> MacroState:
    one = np.ones(3)
    return MacroState(t, np.array([0.0, 500.0, 1000.0]), 0.1 * one, 9.0 * one,
                      0.02 * one, 8.0 * one)


def test_the_meter_is_asked_for_u_over_g_and_the_law_hears_g_times_what_was_applied():
    inner = Told()
    inner.reset()
    ctrl = MeterGain(inner, 2.0)
    first = ctrl.step(_state(0.0))
    assert (first.u, first.u_continuous, first.triggered) == pytest.approx((0.15, 0.2, True))
    second = ctrl.step(_state(1.0), Applied(0.1, -0.05, 0.12))
    assert second.triggered is False and ctrl.log.extra["V"] == [1.5, 1.5]
    assert inner.calls == [("actuated", (0.2,)), ("applied", (0.2, -0.1, 0.24))]
    assert ctrl.set_output_noise(0.01) and inner.calls[-1] == ("noise", (0.02,))
    assert ctrl.name == "told" and ctrl.log.triggers == 1


@pytest.mark.parametrize("gain", [0.0, -1.0, math.nan, math.inf])
def test_a_gain_that_is_not_positive_and_finite_is_refused(gain):
    with pytest.raises(ModelError, match="meter_gain"):
        MeterGain(Told(), gain)
