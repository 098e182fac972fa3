"""Area-occupancy fundamental diagrams (paper, section 2, labels AOrelation and eq. (3)).

Pure vectorised functions of a :class:`ModelParameters` and density arrays (veh/m).
Each family is one function returning Ve_i(AO) and dVe_i/dAO together, so every consumer
(equilibria, characteristic speeds, kernels, the twin's flux, the observer, the
identification) reads the speed and its slope from the same definition:

``power`` (the paper's eq. (3))
    Ve_i(AO) = V_i (1 - (AO / AO_max,i)^gamma_i).

``newell`` (a smoothed Newell triangle in flow, per class)
    C_i(AO) = w_i (AO_jam,i / AO - 1) is Newell's congested branch written in AO: in the
    single-class limit AO = a rho / W it is the speed of the flow w (rho_jam - rho), so
    the slow characteristic Q_e'(rho) tends to -w_i deep in congestion. The free branch
    is V_i; the corner between them is smoothed by the p-norm of order ``corner`` n,
    Ve_i = (V_i^-n + C_i^-n)^(-1/n) = V_i (1 + r^n)^(-1/n), r = V_i / C_i,
    which is smooth on [0, AO_jam,i), equals V_i at AO = 0 and vanishes at the jam
    occupancy. ``ao_max_i`` is that jam occupancy; n -> infinity gives the triangle.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.model.params import ModelParameters

#: (Ve_h, Ve_a, dVe_h/dAO, dVe_a/dAO) at an AO array, m/s and m/s per unit AO
SpeedTerms = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def area_occupancy(p: ModelParameters, rho_h: ArrayLike, rho_a: ArrayLike) -> np.ndarray:
    """AO = (a_h rho_h + a_a rho_a) / W, dimensionless (label AOrelation)."""
    rho_h, rho_a = np.asarray(rho_h, float), np.asarray(rho_a, float)
    return (p.area_h * rho_h + p.area_a * rho_a) / p.road_width


def _power(r: np.ndarray, e: float) -> np.ndarray:
    """r**e for r >= 0, with the half-integer exponents of the presets done by sqrt (fast)."""
    if e == 1.0:
        return r
    if e == 0.5:
        return np.sqrt(r)
    if e == 1.5:
        return r * np.sqrt(r)
    if e == 2.0:
        return r * r
    return r ** e


def _power_speed(v_free: float, ao_max: float, gamma: float, ao: np.ndarray) -> np.ndarray:
    """V (1 - (AO / AO_max)^gamma), m/s."""
    return v_free * (1.0 - _power(ao / ao_max, gamma))


def _power_slope(v_free: float, ao_max: float, gamma: float, ao: np.ndarray) -> np.ndarray:
    """d/dAO of :func:`_power_speed` (infinite at AO = 0 when gamma < 1)."""
    return -v_free * gamma / ao_max * _power(ao / ao_max, gamma - 1.0)


def power_law_speed(ao: ArrayLike, v_free: float, ao_max: float, gamma: float) -> np.ndarray:
    """One class's eq. (3) speed V (1 - (AO / AO_max)^gamma), m/s, AO clipped at 0: the
    power law with its parameters as arguments (fitting one class, drawing a curve)."""
    return _power_speed(v_free, ao_max, gamma, np.maximum(np.asarray(ao, float), 0.0))


def _newell_ratio(v_free: float, w: float, ao_jam: float, ao: np.ndarray) -> np.ndarray:
    """r = V / C(AO) = V AO / (w (AO_jam - AO)): free branch over congested branch."""
    return v_free * ao / (w * (ao_jam - ao))


def _newell_speed(v_free: float, w: float, ao_jam: float, n: float,
                  ao: np.ndarray) -> np.ndarray:
    """V (1 + r^n)^(-1/n), m/s (module docstring)."""
    return v_free * (1.0 + _power(_newell_ratio(v_free, w, ao_jam, ao), n)) ** (-1.0 / n)


def _newell_slope(v_free: float, w: float, ao_jam: float, n: float,
                  ao: np.ndarray) -> np.ndarray:
    """d/dAO of :func:`_newell_speed`: -V r^(n-1) (1 + r^n)^(-1/n-1) dr/dAO."""
    r = _newell_ratio(v_free, w, ao_jam, ao)
    rn1 = _power(r, n - 1.0)
    base = 1.0 + rn1 * r
    dr = v_free * ao_jam / (w * (ao_jam - ao) ** 2)
    return -v_free * rn1 * base ** (-1.0 / n - 1.0) * dr


def _class_args(p: ModelParameters, cls: str) -> tuple[float, ...]:
    """The arguments of the family's per-class functions, without AO."""
    if p.family == "power":
        return (getattr(p, f"v_free_{cls}"), getattr(p, f"ao_max_{cls}"),
                getattr(p, f"gamma_{cls}"))
    return (getattr(p, f"v_free_{cls}"), getattr(p, f"wave_speed_{cls}"),
            getattr(p, f"ao_max_{cls}"), p.corner)


PerClass = Callable[..., np.ndarray]
#: family -> (speed, slope), each f(*class arguments, AO): the one definition of each
_FAMILY: dict[str, tuple[PerClass, PerClass]] = {
    "power": (_power_speed, _power_slope), "newell": (_newell_speed, _newell_slope)}


def speed_of_ao(p: ModelParameters, ao: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(Ve_h(AO), Ve_a(AO)) in m/s for the family ``p.family``."""
    ao = np.asarray(ao, float)
    speed = _FAMILY[p.family][0]
    return speed(*_class_args(p, "h"), ao), speed(*_class_args(p, "a"), ao)


def dspeed_dao(p: ModelParameters, ao: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(dVe_h/dAO, dVe_a/dAO) in m/s per unit AO; both negative for 0 < AO < AO_max,i."""
    ao = np.asarray(ao, float)
    slope = _FAMILY[p.family][1]
    return slope(*_class_args(p, "h"), ao), slope(*_class_args(p, "a"), ao)


def speed_terms_of_ao(p: ModelParameters, ao: ArrayLike) -> SpeedTerms:
    """(Ve_h, Ve_a, dVe_h/dAO, dVe_a/dAO) at ``ao``: what the twin's flux needs."""
    return (*speed_of_ao(p, ao), *dspeed_dao(p, ao))


def equilibrium_speeds(p: ModelParameters, rho_h: ArrayLike,
                       rho_a: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(Ve_h, Ve_a) in m/s at the given class densities (veh/m)."""
    return speed_of_ao(p, area_occupancy(p, rho_h, rho_a))


def speed_jacobian(p: ModelParameters, rho_h: ArrayLike, rho_a: ArrayLike) -> np.ndarray:
    """Partial derivatives of the equilibrium speeds, shape (..., 2, 2), in (m/s)/(veh/m).

    ``out[..., i, j] = dVe_i / drho_j`` with i, j in (h, a). Because Ve_i depends on the
    densities only through AO, ``dVe_i/drho_j = Ve_i'(AO) a_j / W``: the matrix has rank one.
    """
    ao = area_occupancy(p, rho_h, rho_a)
    d_h, d_a = dspeed_dao(p, ao)
    slope = np.stack([d_h, d_a], axis=-1)[..., :, None]            # Ve_i'(AO)
    area = np.array([p.area_h, p.area_a])[None, :] / p.road_width  # a_j / W
    return slope * area
