"""``arzsumo/SumoRampMeter-v0``: the ramp meter in SUMO, one step per control period.

``reset`` prepares the run as ``arzsumo run`` does
(:func:`arzsumo.bridge.session.prepare_run`) and runs the warm-up under the nominal meter;
every ``step`` is one control period of the closed loop of :mod:`arzsumo.bridge.loop`
with the agent's U in the law's place (:mod:`arzsumo.gym.sumo_episode`). docs/gym.md.

An agent's run is prepared as the ``constant`` controller's (:data:`AGENT_RUN`: a law
that is not a PDE law and drives the meter, so the estimate is the full-state one, the
reference twin runs the open loop and the meter follows U) and its summary names the
controller ``"agent"``; an environment standing in for a package law (``law="etc"``, or
made so by :func:`arzsumo.gym.policy`) is prepared as that law's run.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from arzsumo.bridge.prepared import PreparedRun
from arzsumo.bridge.records import micro_fields
from arzsumo.bridge.session import prepare_run
from arzsumo.control.base import Applied, Command, MacroState
from arzsumo.errors import ArzsumoError, EnvError
from arzsumo.gym.base import RampMeterEnv
from arzsumo.gym.options import FRONTENDS, EnvOptions, check_choice, refuse
from arzsumo.gym.rewards import StepRecord
from arzsumo.gym.sumo_episode import SumoEpisode
from arzsumo.units import s_to_h

#: the registry's controller an agent's run is prepared as (module docstring)
AGENT_RUN = "constant"
#: the summary's controller of an agent's episode
AGENT = "agent"


class SumoRampMeterEnv(RampMeterEnv):
    """The ramp meter of ``scenario`` in SUMO (module docstring).

    Parameters
    ----------
    scenario : str, pathlib.Path or Scenario
        A shipped scenario name (``"default"``, ``"stop_and_go_idm"``), a TOML file or a
        :class:`~arzsumo.scenario.Scenario`.
    seed : int, optional
        SUMO's seed of the first episode (default the scenario's ``[sumo] seed``).
    reward : str, mapping or callable
        :mod:`arzsumo.gym.rewards` (default ``"vehicle-hours"``).
    observation : {"state", "loops", "boundary"}
        :mod:`arzsumo.gym.observe`.
    warmup_s, horizon_s : float, optional
        Warm-up under the nominal meter and control horizon, s (default the scenario's
        ``[run] warmup_s`` and ``[sumo] horizon_s``).
    law : str, optional
        The package law episodes stand in for (its run's estimator, reference twin and
        summary); None: an agent.
    frontend : {"libsumo", "traci"}
        libsumo runs one simulation per process (close one environment before resetting
        another); traci runs SUMO in a child process.
    summary : bool
        At the horizon, drain and score the run as ``arzsumo run`` (``info["summary"]``);
        False ends the episode at the horizon without (faster, for training).
    allow_short_warmup : bool
        Accept a warm-up shorter than the scenario's fill phase (``arzsumo run
        --allow-short-warmup``); refused in one line otherwise.
    """

    engine = "sumo"

    def __init__(self, scenario: Any = "default", *, seed: int | None = None,
                 reward: Any = "vehicle-hours", observation: str = "state",
                 warmup_s: float | None = None, horizon_s: float | None = None,
                 law: str | None = None, frontend: str = "libsumo",
                 summary: bool = True, allow_short_warmup: bool = False) -> None:
        super().__init__(EnvOptions.of(scenario, seed, reward, observation, warmup_s,
                                       horizon_s, law))
        self.frontend = check_choice(frontend, "frontend", FRONTENDS)
        for name, flag in (("summary", summary), ("allow_short_warmup", allow_short_warmup)):
            if not isinstance(flag, bool):
                raise refuse(name, flag, "True or False")
        self.allow_short_warmup = allow_short_warmup
        if self.scenario.actuation.actuator != "meter":
            raise refuse("scenario", self.scenario.name, "a scenario whose [actuation] "
                                                         "actuator is the meter")
        self.with_summary = summary
        self._episode: SumoEpisode | None = None
        self._plan_changes = 0
        self._u_loop = (0.0, False)
        self._prepare(self.options.seed)       # refused now, not at the first reset

    def _prepare(self, seed: int | None) -> PreparedRun:
        o = self.options
        try:
            return prepare_run(self.scenario, controller=self.law_name or AGENT_RUN,
                               seed=seed, horizon=o.horizon_s, warmup=o.warmup_s,
                               allow_short_warmup=self.allow_short_warmup)
        except ArzsumoError as exc:
            raise EnvError(f"scenario {self.scenario.name}: {exc}") from None

    def _running_episode(self) -> SumoEpisode:
        if self._episode is None:
            raise EnvError("the environment has no episode running: call reset() first")
        return self._episode

    # -- the engine's stages --------------------------------------------------------------
    def _start(self, seed: int) -> np.ndarray:
        self._episode = ep = SumoEpisode(self._prepare(seed), self.frontend,
                                         self.law_name is not None)
        self.law = ep.c.law if self.law_name is not None else None
        self._plan_changes = 0
        return self._observe()

    def _observe(self) -> np.ndarray:
        ep = self._running_episode()
        s, m = ep.state, ep.c.loop.m
        loops = (None if m.loops is None else
                 self.observer.loop_fields(m.loops.density, m.loops.speed))
        return self.observer(np.vstack([s.rho_h, s.v_h, s.rho_a, s.v_a]), loops)

    def _advance(self, u: float
                 ) -> tuple[StepRecord, np.ndarray, bool, bool, dict[str, Any]]:
        ep = self._running_episode()
        self._u_loop = self.command(u)
        act, meter = ep.step(*self._u_loop)
        loop = ep.c.loop
        c = loop.m.cells
        dx = self.scenario.params.length / c.x.size
        veh_h = float(s_to_h(np.nansum(c.rho_h + c.rho_a) * dx * c.window))
        rec = StepRecord(loop.t, self.period, c.x, micro_fields(c), veh_h, u,
                         act.u_applied, meter.plan_changes - self._plan_changes,
                         float(meter.queue), act.saturated, act.rate_limited)
        self._plan_changes = meter.plan_changes
        info: dict[str, Any] = {"plan_changes": meter.plan_changes, "queue": meter.queue,
                                "max_queue": meter.max_queue,
                                "green_share": meter.green_share, "override": meter.override}
        obs = self._observe()
        done = loop.t >= ep.run.sumo.horizon - 1e-9
        if done:
            info["summary"] = self._finish()
        return rec, obs, False, done, info

    def _finish(self) -> dict[str, Any] | None:
        """The horizon's check, then the run's summary (or SUMO closed without it)."""
        ep = self._running_episode()
        if self.law is not None:
            self._advice = None
            ep.last_check(*self.command(float(self.law_action()[0])))
        else:
            ep.last_check(*self._u_loop)
        self._episode = None
        if not self.with_summary:
            ep.close()
            return None
        from arzsumo.outputs.bridge import summary

        s = summary(ep.finish())
        if not self.law_name:      # an agent's episode: the controller named "agent"
            s = replace(s, identity=replace(s.identity, controller=AGENT),
                        settings={**s.settings, "controller": AGENT})
        return s.to_dict()

    def _close(self) -> None:
        ep, self._episode = getattr(self, "_episode", None), None
        if ep is not None:
            ep.close()

    def _check_law(self) -> Command:
        return self._running_episode().stand_in.advise(self._law_state(), self._told())

    def _law_state(self) -> MacroState:
        ep = self._running_episode()
        return ep.c.loop.acting_on(ep.state)

    def _told(self) -> Applied | None:
        return self._running_episode().c.loop.told
