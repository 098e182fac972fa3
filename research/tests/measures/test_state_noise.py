"""The noisy-state wrapper: what the wrapped controller sees, and its reproducibility."""

import numpy as np
import pytest
from arzsumo_studies.measures.state_noise import NoisyState

from arzsumo.control.base import Controller, MacroState
from arzsumo.errors import ModelError

CELLS = 4000


class Seen(Controller):
    """Records the states it is checked on; U = the mean HV density (veh/s, for tests)."""

    name = "seen"

    def reset(self) -> None:
        super().reset()
        self.states: list[MacroState] = []
        self.applied_calls: list[tuple[float, float, float]] = []
        self.actuated_calls: list[float] = []

    def decide(self, state: MacroState) -> float:
        self.states.append(state)
        u = float(state.rho_h.mean())
        self.log.record(state.t, u, u, True)
        return u

    def applied(self, u, lower=-np.inf, upper=np.inf):
        self.applied_calls.append((u, lower, upper))

    def actuated(self, u):
        self.actuated_calls.append(u)


def state(t: float = 0.0) -> MacroState:
    x = np.linspace(0.0, 1000.0, CELLS)
    one = np.ones(CELLS)
    return MacroState(t, x, 0.1 * one, 10.0 * one, 0.02 * one, 8.0 * one, 0.3)


def test_without_noise_the_wrapped_controller_sees_the_state_as_it_is():
    inner = Seen()
    noisy = NoisyState(inner, 0.0, seed=1)
    assert noisy.check(state()) == pytest.approx(0.1, rel=1e-15)
    seen = inner.states[0]
    np.testing.assert_array_equal(seen.v_a, state().v_a)
    assert noisy.log is inner.log and noisy.name == "seen" and noisy.log.triggers == 1


def test_the_noise_is_relative_white_and_of_the_given_sd_per_field():
    inner = Seen()
    NoisyState(inner, 0.05, seed=3).check(state())
    seen, plain = inner.states[0], state()
    rel = np.array([getattr(seen, f) / getattr(plain, f) - 1.0
                    for f in ("rho_h", "v_h", "rho_a", "v_a")])
    np.testing.assert_allclose(rel.std(axis=1), 0.05, rtol=0.05)      # 4000 cells
    np.testing.assert_allclose(rel.mean(axis=1), 0.0, atol=0.005)
    corr = np.corrcoef(rel)
    assert np.abs(corr[np.triu_indices(4, 1)]).max() < 0.06           # fields independent
    assert seen.occupancy_out == plain.occupancy_out and seen.t == plain.t


def test_the_same_seed_gives_the_same_noise_after_a_reset_and_densities_stay_physical():
    inner = Seen()
    noisy = NoisyState(inner, 2.0, seed=5)
    first = [noisy.check(state(t)) for t in range(3)]
    noisy.reset()
    again = [noisy.check(state(t)) for t in range(3)]
    assert first == again and len(noisy.log.t) == 3
    assert min(float(s.rho_h.min()) for s in inner.states) == 0.0   # clipped, not negative
    other = NoisyState(Seen(), 2.0, seed=6)
    assert [other.check(state(t)) for t in range(3)] != first


def test_what_the_actuator_did_reaches_the_wrapped_controller():
    inner = Seen()
    noisy = NoisyState(inner, 0.01, seed=1)
    noisy.actuated(0.2)
    noisy.applied(0.2, -0.1, 0.3)
    assert inner.actuated_calls == [0.2] and inner.applied_calls == [(0.2, -0.1, 0.3)]


@pytest.mark.parametrize("sd", [-0.01, float("nan"), float("inf")])
def test_a_bad_noise_level_is_refused(sd):
    with pytest.raises(ModelError, match="relative_sd"):
        NoisyState(Seen(), sd, seed=1)
