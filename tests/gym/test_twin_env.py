"""The twin environment: Gymnasium's checks, reproducible seeds, refusals, laws as policies,
and the spaces it shares with the SUMO environment (no SUMO started here)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import arzsumo.gym
from arzsumo.errors import EnvError
from arzsumo.gym import SumoRampMeterEnv, TwinRampMeterEnv, policy
from arzsumo.gym.rewards import StepRecord

HORIZON = 60.0


def _episode(env, seed, act):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(act(obs))
        out += [obs, np.array([reward])]
        done = terminated or truncated
    return out, info


def test_both_ids_are_registered_and_gymnasium_checks_the_twin():
    assert {arzsumo.gym.TWIN_ID, arzsumo.gym.SUMO_ID} <= set(gym.registry)
    env = gym.make(arzsumo.gym.TWIN_ID, horizon_s=HORIZON)
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("observation", ["state", "loops", "boundary"])
def test_the_twin_and_sumo_share_their_spaces(observation):
    twin = TwinRampMeterEnv(observation=observation)
    sumo = SumoRampMeterEnv(observation=observation)     # nothing starts before reset
    assert twin.observation_space == sumo.observation_space
    assert twin.action_space == sumo.action_space
    assert twin.period == sumo.period == 1.0
    shape = {"state": (4, 20), "loops": (4, 5), "boundary": (4, 2)}[observation]
    assert twin.observation_space.shape == shape
    obs, _ = twin.reset(seed=0)
    assert obs.dtype == np.float32 and obs in twin.observation_space
    np.testing.assert_allclose(obs, 1.0, atol=0.1)      # normalised: 1 at equilibrium


def test_reset_with_a_seed_reproduces_an_episode_bit_for_bit():
    env = TwinRampMeterEnv(horizon_s=HORIZON, initial="random", reward="band-power")
    rng = np.random.default_rng(5)
    actions = rng.uniform(env.action_space.low, env.action_space.high, (int(HORIZON), 1))
    it = iter(actions)
    first, _ = _episode(env, 7, lambda obs: next(it))
    it = iter(actions)
    second, _ = _episode(env, 7, lambda obs: next(it))
    assert all(np.array_equal(a, b) for a, b in zip(first, second, strict=True))
    other, _ = env.reset(seed=8)
    assert not np.array_equal(other, first[0])          # another seed, another wave


def test_the_etc_policy_acts_as_the_twin_closed_loop_and_the_summary_scores_it():
    env = TwinRampMeterEnv(horizon_s=HORIZON, initial="random")
    pi = policy("etc", env)
    _, info = _episode(env, 1, pi)
    s = info["summary"]
    assert s["controller"] == "etc" and s["complete"] and s["until_s"] == HORIZON
    assert s["section_veh_h"] == pytest.approx(info["section_veh_h"])
    assert set(s["TTT"]) == {"h", "a", "total"}
    assert env.law is not None and env.law.log.triggers >= 1
    _, open_info = _episode(TwinRampMeterEnv(horizon_s=HORIZON, initial="random"), 1,
                            lambda obs: np.zeros(1))
    assert open_info["summary"]["plan_changes"] == 0


def test_a_callable_and_a_weighted_reward():
    seen = []

    def reward(r: StepRecord) -> float:
        seen.append(r)
        return -r.section_veh_h

    env = TwinRampMeterEnv(horizon_s=5, reward=reward)
    env.reset(seed=0)
    _, rew, *_ = env.step(np.array([0.05]))
    assert rew == -seen[0].section_veh_h and seen[0].u_applied <= 0.05
    both = TwinRampMeterEnv(horizon_s=5, reward={"vehicle-hours": 1.0, "plan-changes": 0.5})
    both.reset(seed=0)
    _, rew2, *_ = both.step(np.array([0.05]))
    assert rew2 == pytest.approx(rew - 0.5)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"scenario": "no_such_scenario"}, "scenario"),
    ({"scenario": 3}, r"scenario = 3 is not allowed"),
    ({"seed": -1}, r"seed = -1 is not allowed: None or an integer"),
    ({"seed": 1.5}, r"seed = 1.5 is not allowed"),
    ({"reward": "speed"}, r"reward = 'speed' is not allowed: .*vehicle-hours"),
    ({"reward": {"vehicle-hours": "1"}}, r"reward = .* is not allowed"),
    ({"observation": "image"}, r"observation = 'image' is not allowed: one of state"),
    ({"horizon_s": 0.5}, r"horizon_s = 0.5 is not allowed: .*>= 1 s"),
    ({"warmup_s": -1}, r"warmup_s = -1 is not allowed"),
    ({"law": "pid"}, r"law = 'pid' is not allowed: one of open"),
    ({"initial": "flat"}, r"initial = 'flat' is not allowed: one of scenario, random"),
])
def test_bad_keyword_arguments_are_refused_in_one_line(kwargs, match):
    with pytest.raises(EnvError, match=match) as err:
        TwinRampMeterEnv(**kwargs)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("action", [np.array([1.0]), np.array([-1.0]), np.array([np.nan]),
                                    np.zeros(2), "fast"])
def test_an_action_outside_the_space_is_refused(action):
    env = TwinRampMeterEnv(horizon_s=5)
    env.reset(seed=0)
    with pytest.raises(EnvError, match=r"action = .* is not allowed: U in \[-0.0833"):
        env.step(action)


def test_stepping_outside_an_episode_and_unknown_policies_are_refused():
    env = TwinRampMeterEnv(horizon_s=2)
    with pytest.raises(EnvError, match="reset"):
        env.step(np.zeros(1))
    with pytest.raises(EnvError, match="policy = 'alinea' is not allowed: on the twin"):
        policy("alinea", env)
    with pytest.raises(EnvError, match=r"env = .* is not allowed"):
        policy("etc", object())
    made = TwinRampMeterEnv(law="etc")
    with pytest.raises(EnvError, match="policy = 'backstepping' is not allowed"):
        policy("backstepping", made)
    pi = policy("etc", env)
    with pytest.raises(EnvError, match="cannot act now"):
        pi(None)


def test_ending_an_episode_early_never_pays():
    """Releasing all the meter can (U at its top, what a learner paid in minus
    vehicle-hours first found) empties the IDM stream's section until the inlet's density
    turns negative and the twin stops at about 125 s. That step is charged the rest of the
    horizon as the section standing jammed, so its return is below the open loop's, which
    runs to the horizon."""
    def episode_return(pick):
        env = gym.make(arzsumo.gym.TWIN_ID, scenario="stop_and_go_idm", initial="random",
                       reward="vehicle-hours")
        env.reset(seed=1)
        total, done, info = 0.0, False, {}
        while not done:
            _, r, terminated, truncated, info = env.step(pick(env))
            total, done = total + r, terminated or truncated
        env.close()
        return total, terminated, info

    drained, ended, info = episode_return(lambda env: env.action_space.high)
    held, ended_held, _ = episode_return(lambda env: np.zeros(1, np.float32))   # U = 0
    assert ended and not ended_held
    assert info["t"] < 200.0 and drained < held
    env = gym.make(arzsumo.gym.TWIN_ID, scenario="stop_and_go_idm")
    sc, rest = env.unwrapped.scenario, env.unwrapped.options.horizon - info["t"]
    eq = sc.equilibrium
    jam = (eq.rho_h + eq.rho_a) * sc.params.ao_max_h / eq.ao * sc.params.length
    assert info["termination_reward"] == pytest.approx(-jam * rest / 3600.0, rel=1e-9)
    env.close()
