"""Equilibria of the mixed-autonomy ARZ model, from class densities or from class demands.

An equilibrium is fixed by the two class densities; the speeds are the fundamental
diagram's Ve_i(AO*) and are never set independently (paper, section 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from scipy.optimize import brentq, minimize_scalar

from arzsumo.errors import DemandError, ModelError, require
from arzsumo.model.fd import area_occupancy, equilibrium_speeds, speed_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.units import ms_to_kmh, veh_s_to_veh_h

Branch = Literal["congested", "free"]

#: Largest relative disagreement between a stated and a computed equilibrium speed.
SPEED_TOLERANCE = 0.02


@dataclass(frozen=True)
class Equilibrium:
    """A uniform equilibrium (rho_h*, v_h*, rho_a*, v_a*) of the model.

    Build it with :func:`equilibrium_from_densities` or :func:`equilibrium_from_demand`.
    Densities in veh/m, speeds in m/s, flows in veh/s.
    """

    params: ModelParameters
    rho_h: float
    rho_a: float

    def __post_init__(self) -> None:
        for name in ("rho_h", "rho_a"):
            value = getattr(self, name)
            require(math.isfinite(value) and value > 0, name, value,
                    "a density greater than 0 veh/m (both classes must be present)")
        ao = self.ao
        require(ao < self.params.ao_max, "AO", round(ao, 6),
                f"below its maximum {self.params.ao_max} (min of ao_max_h, ao_max_a)")

    @property
    def ao(self) -> float:
        """Area occupancy AO* (label AOrelation)."""
        return float(area_occupancy(self.params, self.rho_h, self.rho_a))

    @property
    def v_h(self) -> float:
        """HV equilibrium speed Ve_h(AO*), m/s."""
        return float(speed_of_ao(self.params, self.ao)[0])

    @property
    def v_a(self) -> float:
        """AV equilibrium speed Ve_a(AO*), m/s."""
        return float(speed_of_ao(self.params, self.ao)[1])

    @property
    def q_h(self) -> float:
        """HV flow rho_h* v_h*, veh/s."""
        return self.rho_h * self.v_h

    @property
    def q_a(self) -> float:
        """AV flow rho_a* v_a*, veh/s."""
        return self.rho_a * self.v_a

    @property
    def q(self) -> float:
        """Total flow q_h* + q_a*, veh/s."""
        return self.q_h + self.q_a

    @property
    def penetration(self) -> float:
        """AV penetration rate rho_a* / (rho_h* + rho_a*), dimensionless."""
        return self.rho_a / (self.rho_h + self.rho_a)

    def as_dict(self) -> dict[str, float]:
        """The equilibrium as a flat dict, SI."""
        return {"rho_h": self.rho_h, "rho_a": self.rho_a, "v_h": self.v_h, "v_a": self.v_a,
                "q_h": self.q_h, "q_a": self.q_a, "ao": self.ao, "penetration": self.penetration}


def equilibrium_from_densities(params: ModelParameters, rho_h: float, rho_a: float, *,
                               v_h: float | None = None, v_a: float | None = None,
                               tolerance: float = SPEED_TOLERANCE) -> Equilibrium:
    """The equilibrium at class densities ``rho_h``, ``rho_a`` (veh/m).

    Optional stated speeds ``v_h``, ``v_a`` (m/s) are checked against Ve_i(AO*): a
    disagreement above ``tolerance`` (relative) raises a :class:`ModelError` with both
    numbers, because the model's speeds follow from the densities.
    """
    eq = Equilibrium(params, float(rho_h), float(rho_a))
    for name, stated, computed in (("v_h", v_h, eq.v_h), ("v_a", v_a, eq.v_a)):
        if stated is not None and abs(stated - computed) > tolerance * abs(computed):
            reason = (f"{ms_to_kmh(stated):.2f} km/h disagrees with the fundamental diagram "
                      f"Ve = {ms_to_kmh(computed):.2f} km/h at these densities by more than "
                      f"{tolerance:.0%}; omit the speed or change the densities or parameters")
            exc = ModelError(f"{name} = {reason}")
            exc.field, exc.value, exc.reason = name, stated, reason
            raise exc
    return eq


def _ao_residual(params: ModelParameters, q_h: float, q_a: float, ao: float) -> float:
    """F(AO) = AO - AO(q_h / Ve_h(AO), q_a / Ve_a(AO)); its roots are equilibria."""
    ve_h, ve_a = speed_of_ao(params, ao)
    return ao - (params.area_h * q_h / ve_h + params.area_a * q_a / ve_a) / params.road_width


def demand_capacity_ao(params: ModelParameters, q_h: float, q_a: float) -> tuple[float, float]:
    """AO at which the demand mix comes closest to being carried, and the residual there.

    At fixed class demands the densities are rho_i = q_i / Ve_i(AO); equilibria are the
    roots of F(AO) = AO - (a_h rho_h + a_a rho_a) / W on (0, AO_max). F is negative at
    both ends, so the demand is feasible when max F >= 0; the maximiser separates the
    free branch (smaller AO) from the congested one.
    """
    hi = params.ao_max * (1.0 - 1e-12)
    res = minimize_scalar(lambda ao: -_ao_residual(params, q_h, q_a, ao), bounds=(0.0, hi),
                          method="bounded", options={"xatol": 1e-12})
    return float(res.x), float(-res.fun)


def equilibrium_from_demand(params: ModelParameters, q_h: float, q_a: float,
                            branch: Branch = "congested") -> Equilibrium:
    """The equilibrium carrying class demands ``q_h``, ``q_a`` (veh/s) on one branch.

    Raises :class:`DemandError` when the demand exceeds what the fundamental diagram
    can carry at this class mix.
    """
    for name, value in (("demand_h", q_h), ("demand_a", q_a)):
        require(math.isfinite(value) and value > 0, name, value,
                "a flow greater than 0 veh/s", DemandError)
    require(branch in ("congested", "free"), "branch", branch, "'congested' or 'free'")
    ao_cap, f_cap = demand_capacity_ao(params, q_h, q_a)
    if f_cap < 0.0:
        carried = _max_total_flow(params, q_h / (q_h + q_a))
        raise DemandError(
            f"demand = {veh_s_to_veh_h(q_h + q_a):.0f} veh/h (HV {veh_s_to_veh_h(q_h):.0f}, "
            f"AV {veh_s_to_veh_h(q_a):.0f}) exceeds what the fundamental diagram can carry "
            f"at this mix; allowed: at most {veh_s_to_veh_h(carried):.0f} veh/h"
        )
    lo, hi = (ao_cap, params.ao_max * (1.0 - 1e-12)) if branch == "congested" else (1e-12, ao_cap)
    ao = ao_cap if f_cap == 0.0 else brentq(
        lambda a: _ao_residual(params, q_h, q_a, a), lo, hi, xtol=1e-14, rtol=1e-14)
    ve_h, ve_a = speed_of_ao(params, ao)
    return Equilibrium(params, q_h / float(ve_h), q_a / float(ve_a))


def _max_total_flow(params: ModelParameters, hv_share: float) -> float:
    """Largest total flow (veh/s) the model carries at a given HV share of the demand.

    Feasibility (max F >= 0) is monotone in the total flow at a fixed mix, so bisect.
    """
    lo, hi = 0.0, 100.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        _, f = demand_capacity_ao(params, hv_share * mid, (1 - hv_share) * mid)
        lo, hi = (mid, hi) if f >= 0 else (lo, mid)
    return lo


def _mix_flow(params: ModelParameters, rho: float, penetration: float) -> float:
    """Total equilibrium flow (veh/s) at total density ``rho`` (veh/m) and AV share."""
    rho_h, rho_a = (1.0 - penetration) * rho, penetration * rho
    ve_h, ve_a = equilibrium_speeds(params, rho_h, rho_a)
    return float(rho_h * ve_h + rho_a * ve_a)


def equilibrium_at_penetration(params: ModelParameters, q: float, penetration: float,
                               branch: Branch = "congested") -> Equilibrium:
    """The equilibrium carrying total flow ``q`` (veh/s) with AV density share ``penetration``.

    The penetration rate of section 5 ("Experiments with different AV penetration rates",
    table diffpene) is rho_a* / (rho_h* + rho_a*); the paper keeps "the equilibrium inflow
    the same" while it varies. With rho_h = (1 - p) rho and rho_a = p rho the total flow
    Q(rho) = rho_h Ve_h(AO) + rho_a Ve_a(AO) is zero at rho = 0 and at AO = AO_max and
    has one maximum in between (the capacity at this mix); the congested branch is the
    root of Q(rho) = q above the maximiser, the free branch the one below.

    Parameters
    ----------
    params : ModelParameters
    q : float
        Total equilibrium flow q_h* + q_a*, veh/s (> 0).
    penetration : float
        AV share of the density, in (0, 1).
    branch : {"congested", "free"}

    Raises
    ------
    DemandError
        ``q`` exceeds the capacity at this mix (the message gives the capacity in veh/h).
    """
    require(math.isfinite(q) and q > 0, "flow", q, "a flow greater than 0 veh/s",
            DemandError)
    require(math.isfinite(penetration) and 0.0 < penetration < 1.0, "penetration",
            penetration, "a fraction strictly between 0 and 1")
    require(branch in ("congested", "free"), "branch", branch, "'congested' or 'free'")
    per_veh_area = ((1.0 - penetration) * params.area_h + penetration * params.area_a) \
        / params.road_width                                    # AO per unit total density
    rho_max = params.ao_max / per_veh_area * (1.0 - 1e-12)
    res = minimize_scalar(lambda r: -_mix_flow(params, r, penetration), bounds=(0.0, rho_max),
                          method="bounded", options={"xatol": 1e-12})
    rho_cap, q_cap = float(res.x), float(-res.fun)
    if q > q_cap:
        raise DemandError(
            f"flow = {veh_s_to_veh_h(q):.0f} veh/h is not allowed at penetration "
            f"{penetration:.3f}: at most {veh_s_to_veh_h(q_cap):.0f} veh/h (the capacity "
            "at this mix)")
    lo, hi = (rho_cap, rho_max) if branch == "congested" else (1e-12, rho_cap)
    rho = rho_cap if q == q_cap else brentq(
        lambda r: _mix_flow(params, r, penetration) - q, lo, hi, xtol=1e-15, rtol=1e-14)
    return Equilibrium(params, (1.0 - penetration) * rho, penetration * rho)
