"""The environments' keyword arguments, checked once, each refusal one line.

Both environments take the same arguments (:class:`EnvOptions`); every bad one is an
:class:`arzsumo.errors.EnvError` (a ``ValueError``) naming the argument, the value and
what is allowed, raised by the constructor before anything runs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arzsumo.bridge.road import with_network
from arzsumo.control.registry import controller_names
from arzsumo.errors import ArzsumoError, EnvError
from arzsumo.gym.rewards import reward_of
from arzsumo.scenario import Scenario

#: what the observation holds (:mod:`arzsumo.gym.observe`)
OBSERVATIONS = ("state", "loops", "boundary")
#: what drives SUMO (:mod:`arzsumo.sumo.frontend`); the GUI is not offered to an agent
FRONTENDS = ("libsumo", "traci")
#: the twin's initial condition: the scenario's ``[initial]``, or a random wave per seed
INITIALS = ("scenario", "random")


def refuse(name: str, value: object, allowed: str) -> EnvError:
    """The one-line refusal of argument ``name`` = ``value``."""
    exc = EnvError(f"{name} = {value!r} is not allowed: {allowed}")
    exc.field, exc.value, exc.allowed = name, value, allowed
    return exc


def check_seed(value: object, name: str = "seed") -> int | None:
    """``value`` as a SUMO seed (an integer in [0, 2^31)) or None."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**31:
        raise refuse(name, value, "None or an integer in [0, 2^31)")
    return int(value)


def check_time(value: object, name: str, least: float) -> float | None:
    """``value`` as a time in s (at least ``least``) or None (the scenario's)."""
    if value is None:
        return None
    if (isinstance(value, bool) or not isinstance(value, int | float)
            or not math.isfinite(value) or value < least):
        raise refuse(name, value, f"None (the scenario's) or a time >= {least:g} s")
    return float(value)


def check_choice(value: object, name: str, choices: tuple[str, ...]) -> str:
    """``value``, one of ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise refuse(name, value, f"one of {', '.join(choices)}")
    return value


def scenario_of(value: object) -> Scenario:
    """The scenario ``value`` names: a shipped name, a TOML path or a Scenario."""
    from arzsumo.api.scenarios import load_scenario

    if not isinstance(value, str | Path | Scenario):
        raise refuse("scenario", value, "a shipped scenario name, a TOML file or a Scenario")
    try:
        return load_scenario(value)
    except ArzsumoError as exc:
        raise EnvError(f"scenario: {exc}") from None


@dataclass(frozen=True)
class EnvOptions:
    """The checked keyword arguments of an environment (module docstring; what each is:
    docs/gym.md, "Keyword arguments"). None: the scenario's ``seed``, ``warmup_s`` or
    ``horizon_s``; an agent for ``law``."""

    scenario: Scenario
    seed: int | None
    reward: Callable[..., float] | str | Mapping[str, float]
    observation: str
    warmup_s: float | None
    horizon_s: float | None
    law: str | None = None

    @classmethod
    def of(cls, scenario: Any, seed: Any, reward: Any, observation: Any, warmup_s: Any,
           horizon_s: Any, law: Any = None) -> EnvOptions:
        """Check every argument (module docstring) and resolve the scenario."""
        reward_of(reward)      # refused here, before the scenario is read
        sc = with_network(scenario_of(scenario))   # L, lanes and cells of a [network]
        period = sc.sumo.control_period
        opts = cls(sc, check_seed(seed), reward,
                   check_choice(observation, "observation", OBSERVATIONS),
                   check_time(warmup_s, "warmup_s", 0.0),
                   check_time(horizon_s, "horizon_s", period),
                   None if law is None else check_choice(law, "law", controller_names("sumo")))
        if observation == "loops" and not sc.sensing.loops:
            raise refuse("observation", observation,
                         f"'state' or 'boundary': scenario {sc.name} has no loop stations "
                         "([sensing] kinds without \"loops\")")
        return opts

    @property
    def horizon(self) -> float:
        """The control horizon, s."""
        return self.horizon_s if self.horizon_s is not None else self.scenario.sumo.horizon

