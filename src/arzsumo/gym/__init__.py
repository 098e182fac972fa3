"""The ramp meter as Gymnasium environments: learn on the PDE twin, test in SUMO.

``import arzsumo.gym`` registers ``arzsumo/TwinRampMeter-v0`` (:class:`TwinRampMeterEnv`)
and ``arzsumo/SumoRampMeter-v0`` (:class:`SumoRampMeterEnv`); :func:`policy` offers the
package's controllers as policies. docs/gym.md (``pip install 'arzsumo[gym]'``).
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
