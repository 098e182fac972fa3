"""What the twin and the SUMO environment share: spaces, seeds, actions, rewards, laws.

:class:`RampMeterEnv` is a :class:`gymnasium.Env` whose engine (the PDE twin,
:mod:`arzsumo.gym.twin_env`; SUMO, :mod:`arzsumo.gym.sumo_env`) supplies three stages:
``_start(seed)`` (the episode's first observation), ``_advance(u)`` (one control period
under U) and ``_close()``. Everything the two must agree on lives here: the action space
(U in veh/s, the meter's range cut by ``[actuation] u_max_fraction``), the observation
(:mod:`arzsumo.gym.observe`), the seeds (docs/gym.md, "Seeds"), the rewards
(:mod:`arzsumo.gym.rewards`) and the package laws a policy stands in for (:func:`policy`).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces

from arzsumo.api.controllers import BUILTIN
from arzsumo.control.base import Applied, Command, Controller, MacroState
from arzsumo.control.registry import controller_names
from arzsumo.errors import EnvError
from arzsumo.gym.observe import Observer
from arzsumo.gym.options import EnvOptions, check_seed, refuse
from arzsumo.gym.rewards import StepRecord, reset_reward, reward_of
from arzsumo.scenario import Scenario
from arzsumo.units import VEH_H_PER_VEH_S

#: an action this close (veh/s) outside the space is taken as its bound (float32 rounding)
ACTION_TOLERANCE = 1e-6
#: the package's own laws that run in SUMO, offered as policies (every name of the registry
#: that runs in SUMO is accepted)
POLICIES = tuple(n for n in controller_names("sumo") if n in BUILTIN)


@dataclass(frozen=True)
class Meter:
    """The meter as an agent sees it: the nominal outflow and the range of U (veh/s)."""

    q_nominal: float
    lower: float
    upper: float
    rate_step: float

    @classmethod
    def of(cls, sc: Scenario) -> Meter:
        """The meter of ``sc``'s ``[sumo]`` and ``[actuation]`` (no SUMO started)."""
        from arzsumo.bridge.actuator import ActuationLimits
        from arzsumo.bridge.session import meter_curve_of
        from arzsumo.sumo.green_share import fixed_cycle_u_range
        from arzsumo.sumo.meter_release import one_per_green_u_range

        cfg = sc.sumo
        curve = meter_curve_of(cfg, sc.source)
        q_nom = curve.outflow_at(cfg.green_share)
        lo, hi = (one_per_green_u_range(cfg) if cfg.meter_mode == "one_per_green"
                  else fixed_cycle_u_range(curve, cfg, q_nom))
        limits = ActuationLimits.of(sc.actuation, q_nom, cfg.control_period)
        return cls(q_nom, max(lo, -limits.u_max), min(hi, limits.u_max), limits.rate_step)


class RampMeterEnv(gymnasium.Env):
    """The ramp meter of a scenario, one step per control period (module docstring).

    Subclasses set :attr:`engine` and implement ``_start``, ``_advance``, ``_close``,
    ``_law_state`` and ``_told``.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}
    engine = ""

    def __init__(self, options: EnvOptions) -> None:
        super().__init__()
        self.options = options
        self.scenario = sc = options.scenario
        self.period = sc.sumo.control_period
        self.observer = Observer(options.observation, sc)
        self.observation_space = self.observer.space
        self.meter = Meter.of(sc)
        self.action_space = spaces.Box(self.meter.lower, self.meter.upper, (1,), np.float64)
        self.reward_fn = reward_of(options.reward)
        self.law_name = options.law
        self.law: Controller | None = None
        self._advice: Command | None = None
        self._episodes = 0
        self._running = False
        self.episode_seed: int | None = None
        self.totals: dict[str, float] = {}

    # -- the Gymnasium interface ----------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: Mapping[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode: SUMO's warm-up, or the twin's initial condition."""
        if options:
            raise refuse("options", dict(options), "None or {} (an episode is configured "
                                                    "by the environment's keyword arguments)")
        seed = check_seed(seed, "seed")
        if seed is None and self._episodes == 0:
            seed = (self.options.seed if self.options.seed is not None
                    else self.scenario.sumo.seed)
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(0, 2**31))
        self._close()
        self._running = False
        reset_reward(self.reward_fn)
        self._advice = None
        self.totals = {"section_veh_h": 0.0, "ramp_queue_veh_s": 0.0}
        obs = self._start(episode_seed)
        self.episode_seed, self._running = episode_seed, True
        self._episodes += 1
        return obs, {"t": 0.0, "seed": episode_seed, "engine": self.engine}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """One control period under the U of ``action`` (veh/s)."""
        if not self._running:
            raise EnvError("step() is not allowed now: the episode has not begun or has "
                           "ended; allowed: reset() first")
        u = self.check_action(action)
        try:     # an error anywhere in the step (the engine, the reward) ends the episode
            rec, obs, terminated, truncated, info = self._advance(u)
            reward = float(self.reward_fn(rec))
            rest = self._rest_of_horizon(rec) if terminated else None
            if rest is not None:     # ending early must never pay (see _rest_of_horizon)
                info["termination_reward"] = float(self.reward_fn(rest))
                reward += info["termination_reward"]
        except BaseException:
            self._running = False
            self._close()
            raise
        self.totals["section_veh_h"] += rec.section_veh_h
        self.totals["ramp_queue_veh_s"] += rec.queue * rec.period
        info.update({"t": rec.t, "u_action": rec.u_action, "u_applied": rec.u_applied,
                     "saturated": rec.saturated, "rate_limited": rec.rate_limited,
                     **self.totals})
        if terminated or truncated:
            self._running = False
        return obs, reward, terminated, truncated, info

    def close(self) -> None:
        """End the episode, if one runs (safe to call twice)."""
        self._running = False
        self._close()
        super().close()

    def __del__(self) -> None:   # the last resort; close() is the way out
        with contextlib.suppress(Exception):   # nothing to report to at collection
            self._close()

    # -- actions --------------------------------------------------------------------------
    def check_action(self, action: Any) -> float:
        """U (veh/s) of ``action``: one finite number in the action space, else refused."""
        lo, hi = self.meter.lower, self.meter.upper
        try:
            arr = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError):
            arr = None
        ok = arr is not None and arr.size == 1 and arr.ndim <= 1 and bool(
            np.isfinite(arr).all())
        u = float(arr.reshape(())) if ok and arr is not None else math.nan
        if not ok or not lo - ACTION_TOLERANCE <= u <= hi + ACTION_TOLERANCE:
            raise refuse("action", action,
                         f"U in [{lo:.6g}, {hi:.6g}] veh/s ({lo * VEH_H_PER_VEH_S:.0f} to "
                         f"{hi * VEH_H_PER_VEH_S:.0f} veh/h), an array of shape (1,)")
        return min(max(u, lo), hi)

    # -- package laws ---------------------------------------------------------------------
    def stand_in(self, name: str) -> None:
        """Let episodes from the next reset on stand in for the law ``name`` (a policy's
        set-up, :func:`policy`); an environment made for another law refuses."""
        if self.law_name not in (None, name):
            raise refuse("policy", name, f"{self.law_name!r}: the law this environment "
                                         "was made for (law=...)")
        restart = self.law_name != name and self._running
        self.law_name = name
        if restart:     # the running episode was not made for the law
            self._running = False
            self._close()

    def law_action(self) -> np.ndarray:
        """The law's command at the present check, clipped to the action space (the law
        is checked once per check; :func:`policy`)."""
        if self.law is None or not self._running:
            raise EnvError(f"policy {self.law_name!r} cannot act now: allowed after "
                           "reset(), in an episode begun after the policy was made")
        if self._advice is None:
            self._advice = self._check_law()
        return np.array([min(max(self._advice.u, self.meter.lower), self.meter.upper)])

    def command(self, u: float) -> tuple[float, bool]:
        """The U (veh/s) to actuate for the action ``u`` and whether it is the law's own
        command (the action was the law's, clipped): the law's U before the clip then."""
        adv, self._advice = self._advice, None
        if adv is not None and u == min(max(adv.u, self.meter.lower), self.meter.upper):
            return adv.u, True
        return u, False

    def _check_law(self) -> Command:
        if self.law is None:
            raise EnvError("the environment has no law to check: make one with policy()")
        return self.law.step(self._law_state(), self._told())

    # -- the engine's stages --------------------------------------------------------------
    def _start(self, seed: int) -> np.ndarray:
        raise NotImplementedError

    def _advance(self, u: float
                 ) -> tuple[StepRecord, np.ndarray, bool, bool, dict[str, Any]]:
        raise NotImplementedError

    def _close(self) -> None:
        raise NotImplementedError

    def _rest_of_horizon(self, rec: StepRecord) -> StepRecord | None:
        """The period an episode that ended before its horizon is charged for the rest of
        it (None: nothing to charge)."""
        return None

    def _law_state(self) -> MacroState:
        raise NotImplementedError

    def _told(self) -> Applied | None:
        raise NotImplementedError

    @property
    def state(self) -> MacroState | None:
        """The estimated macroscopic state of the present check (SI), as the package's
        controllers would be handed it; None between episodes."""
        return self._law_state() if self._running else None


class LawPolicy:
    """A package law as a policy of one environment (:func:`policy`)."""

    def __init__(self, name: str, env: RampMeterEnv) -> None:
        self.name, self.env = name, env

    def __call__(self, obs: Any = None) -> np.ndarray:
        """The law's action at the environment's present check (veh/s, shape (1,))."""
        return self.env.law_action()

    def __repr__(self) -> str:
        return f"policy({self.name!r}, {type(self.env).__name__})"


def policy(name: str, env: Any) -> LawPolicy:
    """The package law ``name`` as a policy of ``env``: observation in, action out.

    ``policy("etc", env)`` makes ``env`` stand in for the law from its next ``reset`` and
    returns a callable that returns the law's action at the present check: the law is
    checked on the environment's own state (``env.unwrapped.state``, not the normalised
    observation) and told what the actuator applied, as in ``arzsumo run`` (docs/gym.md,
    "The package's controllers as policies"). Call the policy once per step, with the
    observation of the present check (it reads the environment, not its argument, which is
    there for the Gymnasium convention).

    Parameters
    ----------
    name : str
        ``"open"``, ``"backstepping"``, ``"etc"`` or ``"alinea"`` (any controller of the
        registry that runs in SUMO; on the twin, one that runs on the twin).
    env : gymnasium.Env
        An environment of :mod:`arzsumo.gym` (wrappers allowed).

    Returns
    -------
    LawPolicy
        ``policy(obs) -> action``; reset ``env`` after making it.

    Raises
    ------
    arzsumo.errors.EnvError
        An unknown law, one that does not run on the twin, or an environment made for
        another law.
    """
    base = getattr(env, "unwrapped", env)
    if not isinstance(base, RampMeterEnv):
        raise refuse("env", env, "an environment of arzsumo.gym (arzsumo/TwinRampMeter-v0, "
                                 "arzsumo/SumoRampMeter-v0)")
    allowed = controller_names("twin" if base.engine == "twin" else "sumo")
    if not isinstance(name, str) or name not in allowed:
        raise refuse("policy", name, f"on the {base.engine} one of {', '.join(allowed)}")
    base.stand_in(name)
    return LawPolicy(name, base)
