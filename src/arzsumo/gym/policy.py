"""The package's controllers as policies: observation in, action out.

``policy("etc", env)`` makes ``env`` stand in for the law from its next ``reset`` and
returns a callable that returns the law's action at the present check: the law is
checked on the environment's own state (``env.unwrapped.state``, not the normalised
observation) and told what the actuator applied, as in ``arzsumo run`` (docs/gym.md,
"The package's controllers as policies"). Call the policy once per step, with the
observation of the present check (it reads the environment, not its argument, which is
there for the Gymnasium convention).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from arzsumo.api.controllers import BUILTIN
from arzsumo.control.registry import controller_names
from arzsumo.gym.base import RampMeterEnv
from arzsumo.gym.options import refuse

#: the package's own laws that run in SUMO, offered as policies (every name of the registry
#: that runs in SUMO is accepted)
POLICIES = tuple(n for n in controller_names("sumo") if n in BUILTIN)


class LawPolicy:
    """A package law as a policy of one environment (module docstring)."""

    def __init__(self, name: str, env: RampMeterEnv) -> None:
        self.name, self.env = name, env

    def __call__(self, obs: Any = None) -> np.ndarray:
        """The law's action at the environment's present check (veh/s, shape (1,))."""
        return self.env.law_action()

    def __repr__(self) -> str:
        return f"policy({self.name!r}, {type(self.env).__name__})"


def policy(name: str, env: Any) -> LawPolicy:
    """The package law ``name`` as a policy of ``env`` (module docstring).

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
