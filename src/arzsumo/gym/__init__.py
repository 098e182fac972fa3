"""The ramp meter as Gymnasium environments: learn on the PDE twin, test in SUMO.

``import arzsumo.gym`` registers two environments with the same spaces, period and
action range on a scenario (``pip install 'arzsumo[gym]'``; a first episode: docs/gym.md):
``arzsumo/TwinRampMeter-v0`` (:class:`TwinRampMeterEnv`, the nonlinear PDE twin) and
``arzsumo/SumoRampMeter-v0`` (:class:`SumoRampMeterEnv`, SUMO with the closed loop of
``arzsumo run``: warm-up in ``reset``; ``close`` leaves no SUMO running). :func:`policy`
offers the package's controllers as policies, :mod:`arzsumo.gym.rewards` the named
rewards and :class:`StepRecord`, :mod:`arzsumo.gym.observe` the observations.
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - the extra is missing
    raise ImportError("arzsumo.gym needs gymnasium: pip install 'arzsumo[gym]'") from exc

from arzsumo.gym.base import POLICIES, LawPolicy, RampMeterEnv, policy
from arzsumo.gym.observe import denormalise
from arzsumo.gym.rewards import NAMED as REWARDS
from arzsumo.gym.rewards import StepRecord
from arzsumo.gym.sumo_env import SumoRampMeterEnv
from arzsumo.gym.twin_env import TwinRampMeterEnv

#: the registered ids
TWIN_ID, SUMO_ID = "arzsumo/TwinRampMeter-v0", "arzsumo/SumoRampMeter-v0"


def _register() -> None:
    for env_id, entry in ((TWIN_ID, "arzsumo.gym.twin_env:TwinRampMeterEnv"),
                          (SUMO_ID, "arzsumo.gym.sumo_env:SumoRampMeterEnv")):
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=entry)


_register()

__all__ = ["POLICIES", "REWARDS", "SUMO_ID", "TWIN_ID", "LawPolicy", "RampMeterEnv",
           "StepRecord", "SumoRampMeterEnv", "TwinRampMeterEnv", "denormalise", "policy"]
