"""Dynamic ETC and observer-based ETC on the linear plant (section 4)."""

import numpy as np
import pytest

from arzsumo.control.base import ControlLog
from arzsumo.control.etc import PAPER_DESIGN, EtcDesign, EventTrigger, integrate_m
from arzsumo.control.events import event_summary, lyapunov_convergence_time, release_time
from arzsumo.control.observer import BoundaryObserver, dual_system, observer_gains
from arzsumo.control.verify import run_closed_loop
from arzsumo.errors import ModelError
from arzsumo.model.characteristic import CharacteristicSystem
from tests.control.conftest import N_CELLS


@pytest.fixture(scope="module")
def etc_run(lin, kernels):
    return run_closed_loop(lin, kernels, "etc", period=1.0)


@pytest.fixture(scope="module")
def obs_run(lin, kernels):
    return run_closed_loop(lin, kernels, "observer-etc", period=1.0)


def test_etc_stabilises_with_far_fewer_updates(etc_run):
    s = etc_run.summary()
    assert s["V_ratio"] < 1e-3                       # V decays
    assert s["triggers"] < 250                       # well below one per check (450)
    assert s["min_interval"] >= 1.0 - 1e-9           # never faster than the check period
    assert s["release_time"] == pytest.approx(450 - s["triggers"] * 1.0)


def test_m_is_negative_between_events(etc_run):
    """Lemma mbound holds at every check that does not trigger; with 1 s checks the
    threshold is crossed unseen, so m can be >= 0 at triggering checks: counted, not hidden."""
    m = np.array(etc_run.log.extra["m"])
    triggered = np.array(etc_run.log.triggered)
    assert np.all(m[~triggered] < 0)
    assert etc_run.summary()["m_nonnegative_checks"] == int(np.sum(m >= 0))


def test_faster_checks_trigger_more(lin, kernels, etc_run):
    fast = run_closed_loop(lin, kernels, "etc", period=0.1, horizon=450.0)
    assert fast.log.triggers > etc_run.log.triggers
    assert fast.summary()["min_interval"] >= 0.1 - 1e-9


def test_continuous_backstepping_updates_every_period(lin, kernels):
    run = run_closed_loop(lin, kernels, "backstepping", period=1.0, horizon=60.0)
    assert run.log.triggers == 60 and run.summary()["release_time"] == 0.0


def test_observer_error_collapses_after_its_convergence_time(lin, obs_run):
    t, err = obs_run.t, obs_run.estimation_error
    t_f = lin.system.t_f
    assert err[0] == pytest.approx(1.0)
    assert err[t < t_f * 0.5].min() > 1e-2
    assert err[t > t_f + 10].max() < 5e-3           # orders of magnitude below the start


def test_observer_etc_triggers_more_than_full_state_etc(etc_run, obs_run):
    assert obs_run.log.triggers > etc_run.log.triggers
    assert obs_run.summary()["V_ratio"] < 1e-2


def _estimation_error(system, n_cells, gains_on=True):
    from arzsumo.control.plant import LinearPlant

    x = np.linspace(0, system.length, n_cells + 1)
    truth = np.vstack([np.sin(2 * np.pi * x / system.length) * (k + 1) * 0.1 for k in range(4)])
    plant = LinearPlant(system, n_cells)
    plant.reset(truth)
    obs = BoundaryObserver(system, n_cells)
    if not gains_on:
        obs.gains = 0 * obs.gains
    obs.advance(0.0, plant.state[-1, 0], 0.0)
    while plant.t < system.t_f + 50:
        plant.step(lambda t, w: 0.0)
        obs.advance(plant.t, plant.state[-1, 0], 0.0)
    return np.linalg.norm(plant.state - obs.estimate) / np.linalg.norm(truth)


def test_observer_kernels_give_finite_time_estimation_on_a_coupled_system(lin):
    """Sigma+- = 0 in the ARZ model makes P = 0; give the system a w- -> w+ coupling and
    check that the gains from the dual kernels drive the error to zero after t_f (up to
    the first-order error of the explicit injection, which halves with h)."""
    s = lin.system
    j = s.j_hat.copy()
    j[:3, 3] = [0.01, -0.02, 0.015]
    coupled = CharacteristicSystem(s.lam, j, s.Q, s.R, s.length)
    assert np.abs(observer_gains(coupled, 50)).max() > 1e-3
    coarse, fine = _estimation_error(coupled, 50), _estimation_error(coupled, 100)
    assert fine < 0.6 * coarse
    assert fine < 0.1 * _estimation_error(coupled, 100, gains_on=False)


def test_without_coupling_the_observer_is_exact(lin):
    assert _estimation_error(lin.system, 100) < 1e-6


def test_dual_system_is_an_involution(lin):
    twice = dual_system(dual_system(lin.system))
    np.testing.assert_allclose(twice.j_hat, lin.system.j_hat, rtol=1e-12, atol=1e-18)


def test_m_integration_is_exact_for_linear_forcing():
    eta, tau = 0.9, 1.3
    ts = np.linspace(0, tau, 20001)
    g = 0.2 + 0.5 * ts / tau
    m = -0.01
    for k in range(ts.size - 1):            # fine RK4-free reference: exponential Euler
        dt = ts[k + 1] - ts[k]
        m = m * np.exp(-eta * dt) + 0.5 * (g[k] + g[k + 1]) * (1 - np.exp(-eta * dt)) / eta
    assert integrate_m(-0.01, 0.2, 0.7, eta, tau) == pytest.approx(m, rel=1e-7)


def test_release_time_of_an_empty_log_is_the_horizon():
    # no check, no update: the control was held all along (T - N Delta with N = 0)
    assert release_time([], [], 450.0) == 450.0
    assert event_summary(ControlLog(), 450.0).release_time == 450.0


def test_release_time_and_lyapunov_time_definitions():
    log = ControlLog()
    for t, trig in [(0, True), (1, False), (2, False), (3, True), (4, False)]:
        log.record(t, 0, 0, trig)
    assert release_time(log.t, log.triggered, 5.0) == 3.0
    t = np.arange(6.0)
    assert lyapunov_convergence_time(t, np.array([1, 0.5, 0.001, 0.02, 0.001, 0.0])) == 4.0


@pytest.mark.parametrize(("changes", "match"), [
    ({"zeta": 0.0}, r"zeta = 0.0"),
    ({"m0": 0.1}, r"m0 = 0.1 .*negative"),
    ({"varsigma": (1.0, 1.0)}, r"varsigma .* 4 values"),
    ({"rho": 1.0}, r"unknown design parameter"),
])
def test_bad_design_parameters(changes, match):
    with pytest.raises(ModelError, match=match):
        PAPER_DESIGN.with_(**changes)


def test_first_check_is_an_event(lin, kernels):
    trig = EventTrigger(lin.system, kernels, EtcDesign())
    w = np.ones((4, N_CELLS + 1)) * 1e-3
    r = trig.check(0.0, w)
    assert r.triggered and r.u_bar_held == r.u_bar_continuous
    again = trig.check(1.0, w)               # same state: no discrepancy, no event
    assert not again.triggered and again.d == 0.0


def test_m_integrates_the_first_interval_whatever_the_clock_origin(lin, kernels):
    """mdyna depends on elapsed time only: the same two checks 1 s apart give the same m
    whether the first falls at t = 0 or at t = 5 s, and m has moved from m(0)."""
    w, w2 = np.full((4, N_CELLS + 1), 1e-3), np.full((4, N_CELLS + 1), 2e-3)
    ms = []
    for t0 in (0.0, 5.0):
        trig = EventTrigger(lin.system, kernels, EtcDesign())
        trig.check(t0, w)
        ms.append(trig.check(t0 + 1.0, w2).m)
    assert ms[0] == pytest.approx(ms[1], rel=1e-12)
    assert ms[0] != EtcDesign().m0


def test_output_noise_sd_recovers_white_noise_under_a_slow_signal_and_a_few_steps():
    from arzsumo.control.etc import output_noise_sd
    rng = np.random.default_rng(11)
    t = np.arange(3000.0)
    noise = 0.05 * rng.standard_normal(t.size)
    slow = 0.4 * np.sin(2 * np.pi * t / 600.0) + 1e-4 * t          # what a law follows
    steps = np.where(t > 1500, 0.8, 0.0) + np.where(t > 2200, -0.5, 0.0)
    assert output_noise_sd(noise) == pytest.approx(0.05, rel=0.06)
    assert output_noise_sd(noise + slow + steps) == pytest.approx(0.05, rel=0.06)
    assert output_noise_sd(slow) < 0.1 * 0.05            # its slope, a tenth of the noise
    assert np.isnan(output_noise_sd(np.array([1.0, np.nan, 2.0])))


def test_the_measured_dead_band_is_noise_k_root_two_times_the_output_noise(lin, kernels):
    import math
    design = EtcDesign(noise_k=2.5, noise_from_estimate=True)
    trig = EventTrigger(lin.system, kernels, design)
    assert trig.dead_band == 0.0                        # not measured yet: the paper's
    assert trig.set_output_noise(0.01) == pytest.approx(2.5 * math.sqrt(2.0) * 0.01)
    trig.reset()                                        # a new run keeps the measured band
    assert trig.dead_band == pytest.approx(2.5 * math.sqrt(2.0) * 0.01)
    with pytest.raises(ModelError, match="output noise"):
        trig.set_output_noise(-1.0)
    with pytest.raises(ModelError, match="noise_from_estimate"):
        design.with_(noise_sd=(1.0, 1.0, 1.0, 1.0))


def test_acted_energy_is_the_least_v_that_gives_the_laws_output(lin, kernels):
    """V_U = U-bar^2 / (h^T W^-1 h) is the minimum of V over target states with the same
    U-bar: no random state goes below it, and the minimiser W^-1 h reaches it."""
    trig = EventTrigger(lin.system, kernels, PAPER_DESIGN.with_(trigger_energy="acted"))
    per_u2, lyap, law = trig.acted_per_u2, trig.lyapunov, trig.law
    assert per_u2 == lyap.least_per_u2(law) > 0
    rng = np.random.default_rng(7)
    n, size = lin.system.n, kernels.n_cells + 1
    for _ in range(20):
        alpha, beta = rng.normal(size=(n, size)), rng.normal(size=size)
        u = law.u_bar_from_target(alpha, beta)
        assert lyap(alpha, beta) >= per_u2 * u * u * (1 - 1e-12)
    h = law.target_gain.copy()
    h[:n, -1] -= lin.system.R
    z = h / lyap.weights                                  # W^-1 h
    u = law.u_bar_from_target(z[:n], z[n])
    assert lyap(z[:n], z[n]) == pytest.approx(per_u2 * u * u, rel=1e-10)
    assert EventTrigger(lin.system, kernels).acted_per_u2 == 0.0     # the paper's V


def test_acted_trigger_keeps_the_guarantee(lin, kernels, etc_run):
    """Theorem esthm's decay and Lemma mbound with V_U in defdynamic and mdyna; with the
    paper's design m's memory dominates both energies, and the runs barely differ."""
    acted = run_closed_loop(lin, kernels, "etc", period=1.0,
                            design=PAPER_DESIGN.with_(trigger_energy="acted"))
    s = acted.summary()
    assert s["V_ratio"] < 1e-3                                   # V still decays
    assert acted.log.triggers < 450                              # still event-triggered
    assert abs(acted.log.triggers - etc_run.log.triggers) <= 0.1 * etc_run.log.triggers
    m = np.array(acted.log.extra["m"])
    assert np.all(m[~np.array(acted.log.triggered)] < 0)         # Lemma mbound between events


def test_unknown_trigger_energy_is_refused():
    with pytest.raises(ModelError, match="trigger_energy"):
        EtcDesign(trigger_energy="output")


def test_band_trigger_fires_exactly_when_the_hold_error_leaves_the_band(lin, kernels):
    """trigger = band: an event iff |d| > delta, whatever V and m say; with delta = 0 it
    is backstepping sampled at every check whose law moved."""
    design = PAPER_DESIGN.with_(trigger="band")
    run = run_closed_loop(lin, kernels, "etc", period=1.0, horizon=60.0, design=design)
    assert run.log.triggers == 60                           # delta = 0: every check
    trig = EventTrigger(lin.system, kernels, design)
    delta = trig.set_output_noise(0.05)                     # m/s of U-bar
    rng = np.random.default_rng(1)
    w = rng.normal(size=(lin.system.n + 1, kernels.n_cells + 1))
    gain = trig.law.gain
    first = trig.check(0.0, w)
    assert first.triggered
    for k, target in enumerate((0.5 * delta, 0.99 * delta, 1.01 * delta, -2 * delta), 1):
        # a state whose law differs from the held U-bar by ``target``
        shift = (first.u_bar_continuous + target - trig.law.u_bar(w)) / np.sum(gain * gain)
        r = trig.check(float(k), w + shift * gain)
        assert r.d == pytest.approx(-target, abs=1e-9) or r.triggered
        assert r.triggered == (abs(target) > delta)
        if r.triggered:
            break


def test_band_trigger_refuses_an_energy_it_does_not_read():
    with pytest.raises(ModelError, match="trigger_energy"):
        EtcDesign(trigger="band", trigger_energy="acted")
    with pytest.raises(ModelError, match="trigger"):
        EtcDesign(trigger="static")
