"""The mixed-autonomy ARZ model: parameters, fundamental diagram, equilibria, characteristic form.

Pure math: no SUMO, no files, no plotting. May import only ``units`` and ``errors``
(contracts in ``pyproject.toml``, checked by ``lint-imports``).
"""

from arzsumo.model.characteristic import (
    CharacteristicSystem,
    Linearization,
    characteristic_speeds,
    linearize,
)
from arzsumo.model.equilibrium import (
    Equilibrium,
    equilibrium_at_penetration,
    equilibrium_from_demand,
    equilibrium_from_densities,
)
from arzsumo.model.fd import area_occupancy, equilibrium_speeds, speed_jacobian
from arzsumo.model.params import PRESETS, VARIABLES, ModelParameters, Preset, get_preset

__all__ = [
    "PRESETS",
    "VARIABLES",
    "CharacteristicSystem",
    "Equilibrium",
    "Linearization",
    "ModelParameters",
    "Preset",
    "area_occupancy",
    "characteristic_speeds",
    "equilibrium_at_penetration",
    "equilibrium_from_demand",
    "equilibrium_from_densities",
    "equilibrium_speeds",
    "get_preset",
    "linearize",
    "speed_jacobian",
]
