"""The mixed-autonomy ARZ model: parameters, fundamental diagram, equilibria, characteristic form.

Pure math: no SUMO, no files, no plotting. May import only ``units`` and ``errors``
(contracts in ``pyproject.toml``, checked by ``lint-imports``).
"""

from arzsumo.model.characteristic import (
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
from arzsumo.model.fd import area_occupancy, speed_jacobian
from arzsumo.model.params import PRESETS, ModelParameters, get_preset

__all__ = [
    "PRESETS",
    "Equilibrium",
    "Linearization",
    "ModelParameters",
    "area_occupancy",
    "characteristic_speeds",
    "equilibrium_at_penetration",
    "equilibrium_from_demand",
    "equilibrium_from_densities",
    "get_preset",
    "linearize",
    "speed_jacobian",
]
