"""Physical parameters of the mixed-autonomy ARZ model (paper, section 2) and named presets.

All fields are SI: metres, seconds, m/s. The presets come from the paper's
"Simulation settings" subsection (section 5). The paper never states the vehicle width d:
the default 2.0 m and what it gives against the paper's speeds are in
docs/characteristic_form.md, section 6. Speeds always follow from the fundamental diagram.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from arzsumo.errors import ModelError, require
from arzsumo.units import kmh_to_ms, veh_km_to_veh_m

#: the fundamental-diagram families (:mod:`arzsumo.model.fd`): the paper's power law and a
#: smoothed Newell triangle whose congested branch carries a given wave speed
FAMILIES = ("power", "newell")
#: the fields only the ``newell`` family reads
NEWELL_FIELDS = ("wave_speed_h", "wave_speed_a", "corner")
#: the fields only the ``power`` family reads
POWER_FIELDS = ("gamma_h", "gamma_a")

#: the macroscopic fields, in the storage order of every field array of the package:
#: HV density (veh/m), HV speed (m/s), AV density (veh/m), AV speed (m/s)
VARIABLES = ("rho_h", "v_h", "rho_a", "v_a")


def _positive(name: str, value: float) -> None:
    require(isinstance(value, int | float) and math.isfinite(value) and value > 0,
            name, value, "a finite number greater than 0")


@dataclass(frozen=True)
class ModelParameters:
    """Parameters of the 4x4 mixed-autonomy ARZ model with the AO fundamental diagram.

    Parameters
    ----------
    length : float
        Road length L, m.
    road_width : float
        Road width W, m (label AOrelation).
    vehicle_width : float
        Vehicle width d, m, the same for both classes (labels impactHV, impactAV).
    spacing_h, spacing_a : float
        Spacing policies s_h, s_a, m.
    tau_h, tau_a : float
        Relaxation times, s.
    gamma_h, gamma_a : float
        Traffic pressure exponents of the fundamental diagram, dimensionless.
    ao_max_h, ao_max_a : float
        Maximum area occupancies, dimensionless, in (0, 1].
    v_free_h, v_free_a : float
        Free-flow speeds V_h, V_a, m/s.
    family : {"power", "newell"}
        Fundamental-diagram family (:mod:`arzsumo.model.fd`). ``power`` is the paper's
        eq. (3): ``gamma_i`` shape it and ``ao_max_i`` is where the speed reaches 0.
        ``newell`` is a smoothed Newell triangle: ``ao_max_i`` is its jam occupancy.
    wave_speed_h, wave_speed_a : float
        ``newell`` only: magnitude w_i of the congested branch's wave speed, m/s (the
        slow characteristic tends to -w_i deep in congestion).
    corner : float
        ``newell`` only: order n >= 1 of the p-norm that smooths the triangle's corner
        (default 6: on SUMO's default stream lambda_4 moves by under 1 % from 6 to 12,
        and the data do not pin it).
    """

    length: float = 1000.0
    road_width: float = 6.5
    vehicle_width: float = 2.0
    spacing_h: float = 8.0
    spacing_a: float = 15.0
    tau_h: float = 30.0
    tau_a: float = 60.0
    gamma_h: float = 2.5
    gamma_a: float = 2.0
    ao_max_h: float = 0.9
    ao_max_a: float = 0.85
    v_free_h: float = 80.0 / 3.6
    v_free_a: float = 60.0 / 3.6
    family: str = "power"
    wave_speed_h: float = 33.0 / 3.6
    wave_speed_a: float = 33.0 / 3.6
    corner: float = 6.0

    def __post_init__(self) -> None:
        require(self.family in FAMILIES, "family", self.family,
                f"one of {', '.join(FAMILIES)}")
        for f in fields(self):
            if f.name != "family":
                _positive(f.name, getattr(self, f.name))
        require(self.corner >= 1.0, "corner", self.corner, "an order n >= 1")
        for name in ("ao_max_h", "ao_max_a"):
            value = getattr(self, name)
            require(value <= 1.0, name, value, "an area occupancy in (0, 1]")
        require(self.vehicle_width <= self.road_width, "vehicle_width", self.vehicle_width,
                f"at most the road width {self.road_width} m")

    @property
    def area_h(self) -> float:
        """Impact area of an HV, a_h = d s_h, m^2 (label impactHV)."""
        return self.vehicle_width * self.spacing_h

    @property
    def area_a(self) -> float:
        """Impact area of an AV, a_a = d s_a, m^2 (label impactAV)."""
        return self.vehicle_width * self.spacing_a

    @property
    def ao_max(self) -> float:
        """Largest AO at which both equilibrium speeds stay positive."""
        return min(self.ao_max_h, self.ao_max_a)

    @property
    def ignored_fields(self) -> tuple[str, ...]:
        """The fields this family does not read (a scenario that sets one is refused)."""
        return NEWELL_FIELDS if self.family == "power" else POWER_FIELDS

    def with_(self, **changes: float | str) -> ModelParameters:
        """A copy with some fields changed (validated again)."""
        unknown = set(changes) - {f.name for f in fields(self)}
        if unknown:
            allowed = ", ".join(f.name for f in fields(self))
            raise ModelError(f"unknown model parameter(s) {sorted(unknown)}; allowed: {allowed}")
        return replace(self, **changes)


@dataclass(frozen=True)
class Preset:
    """A named model: its parameters and its equilibrium densities (veh/m)."""

    name: str
    params: ModelParameters
    rho_h: float
    rho_a: float
    description: str


_BASE = ModelParameters()
#: the paper's equilibrium densities, 110 HV/km and 95 AV/km, in veh/m
_RHO_H, _RHO_A = float(veh_km_to_veh_m(110)), float(veh_km_to_veh_m(95))

PRESETS: dict[str, Preset] = {preset.name: preset for preset in (
    Preset("paper_base", _BASE, _RHO_H, _RHO_A,
           "Section 5 base case: s_h = 8 m, s_a = 15 m, 110 HV/km and 95 AV/km"),
    Preset("paper_s12", _BASE.with_(spacing_a=12.0), _RHO_H, _RHO_A,
           "Different spacing policy: s_a = 12 m (paper's stated speeds 48 and 28 km/h)"),
    # The paper says the aggressive case "adjusts accordingly" the free-flow speeds and
    # maximum AOs without giving them; we swap the class behaviours along with the
    # spacings (HV: 60 km/h, AO_max 0.85; AV: 80 km/h, AO_max 0.9).
    Preset("paper_aggressive",
           _BASE.with_(spacing_h=15.0, spacing_a=8.0, v_free_h=float(kmh_to_ms(60)),
                       v_free_a=float(kmh_to_ms(80)), ao_max_h=0.85, ao_max_a=0.9),
           _RHO_H, _RHO_A,
           "Aggressive AV spacing: s_h = 15 m, s_a = 8 m, class behaviours swapped"),
)}


def get_preset(name: str) -> Preset:
    """The preset called ``name``; a :class:`ModelError` lists the known ones otherwise."""
    try:
        return PRESETS[name]
    except KeyError:
        raise ModelError(
            f"preset = {name!r} is unknown; allowed: {', '.join(sorted(PRESETS))}"
        ) from None
