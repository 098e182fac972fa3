"""The SUMO environment: Gymnasium's checks, the ETC policy's episode equal to ``arzsumo
run --controller etc`` key for key, reproducible seeds, and no SUMO left behind by a
closed or interrupted episode. Short runs: warm-ups of 10-60 s, horizons of 5-60 s."""

from __future__ import annotations

import libsumo
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from arzsumo.api.scenarios import load_scenario
from arzsumo.bridge.session import run_in_sumo
from arzsumo.errors import EnvError
from arzsumo.gym import SumoRampMeterEnv, policy
from arzsumo.io import json_safe
from arzsumo.outputs.bridge import summary

pytestmark = pytest.mark.sumo

#: summary keys that time the run's wall clock: never equal between two runs
WALL_CLOCK = {"wall_time", "timings", "controller_time_per_period"}


def _short(**kwargs):
    return SumoRampMeterEnv(warmup_s=10, horizon_s=5, summary=False,
                            allow_short_warmup=True, **kwargs)


def _steps(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        obs, reward, _, truncated, info = env.step(a)
        out += [obs, np.array([reward, info["u_applied"], info["queue"]])]
    return out, truncated


def test_gymnasium_checks_the_sumo_environment_and_close_leaves_no_sumo():
    env = _short()
    check_env(env, skip_render_check=True)
    env.close()
    env.close()                                 # twice is safe
    assert not libsumo.simulation.isLoaded()


def test_the_etc_policy_gives_the_summary_of_arzsumo_run_key_for_key():
    env = SumoRampMeterEnv("default", warmup_s=60, horizon_s=60, allow_short_warmup=True)
    pi = policy("etc", env)
    obs, _ = env.reset(seed=3)
    done, steps = False, 0
    while not done:
        obs, _, terminated, truncated, info = env.step(pi(obs))
        done, steps = terminated or truncated, steps + 1
    env.close()
    got = json_safe(info["summary"])
    ran = run_in_sumo(load_scenario("default"), controller="etc", seed=3, horizon=60,
                      warmup=60, allow_short_warmup=True)
    want = json_safe(summary(ran.result).to_dict())
    assert steps == 60 and got.keys() == want.keys()
    assert {k: got[k] for k in got if k not in WALL_CLOCK} == \
        {k: want[k] for k in want if k not in WALL_CLOCK}
    assert got["controller"] == "etc"


def test_reset_with_a_seed_reproduces_an_episode_bit_for_bit():
    env = _short(reward="band-power")
    actions = [np.array([u]) for u in (0.05, -0.05, 0.0, 0.08, 0.02)]
    first, truncated = _steps(env, 11, actions)
    second, _ = _steps(env, 11, actions)
    env.close()
    assert truncated
    assert all(np.array_equal(a, b) for a, b in zip(first, second, strict=True))


def test_an_agents_episode_is_scored_and_labelled_agent():
    env = SumoRampMeterEnv(warmup_s=10, horizon_s=5, allow_short_warmup=True)
    _, _ = env.reset(seed=2)
    for _ in range(5):
        *_, info = env.step(np.array([0.05]))
    env.close()
    s = info["summary"]
    assert s["controller"] == "agent" and s["settings"]["controller"] == "agent"
    assert s["actuation"]["applies"] and s["horizon"] == 5.0


def test_an_interrupted_episode_leaves_no_sumo_and_sumo_starts_again():
    def failing(record):
        if record.t >= 2:
            raise KeyboardInterrupt
        return 0.0

    env = _short(reward=failing)
    env.reset(seed=1)
    env.step(np.zeros(1))
    with pytest.raises(KeyboardInterrupt):
        env.step(np.zeros(1))
    assert not libsumo.simulation.isLoaded()
    quitter = _short()
    quitter.reset(seed=1)
    quitter.step(np.zeros(1))
    assert libsumo.simulation.isLoaded()
    quitter.close()                             # closed before the horizon
    assert not libsumo.simulation.isLoaded()
    again = _short()
    again.reset(seed=1)                         # a new simulation starts in this process
    again.close()
    assert not libsumo.simulation.isLoaded()


def test_a_short_warmup_is_refused_as_arzsumo_run_refuses_it():
    with pytest.raises(EnvError, match=r"warmup = 10 is not allowed: .*fill phase"):
        SumoRampMeterEnv(warmup_s=10)
    with pytest.raises(EnvError, match=r"allow_short_warmup = 1 is not allowed"):
        SumoRampMeterEnv(allow_short_warmup=1)


def test_an_unclosed_episode_is_closed_by_the_next_reset():
    env = _short()
    env.reset(seed=1)
    env.step(np.zeros(1))
    env.reset(seed=2)                           # the first episode's SUMO closed first
    env.close()
    assert not libsumo.simulation.isLoaded()
