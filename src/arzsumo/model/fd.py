"""Area-occupancy fundamental diagrams (paper, section 2, labels AOrelation and eq. (3)).

Pure vectorised functions of a :class:`ModelParameters` and density arrays (veh/m). Each
family defines its speed Ve_i(AO) and slope dVe_i/dAO once (:data:`_FAMILY`), for every
consumer:

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
    """V (1 - (AO / AO_max)^gamma), m/s; finite at AO = 0 for every gamma > 0."""
    return v_free * (1.0 - _power(ao / ao_max, gamma))


def _power_terms(v_free: float, ao_max: float, gamma: float,
                 ao: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The power law's speed and slope dVe/dAO with one power (the twin's hot path; for
    AO > 0: at AO = 0 with gamma < 1 the slope is infinite)."""
    r = ao / ao_max
    pm = _power(r, gamma - 1.0)
    return v_free * (1.0 - pm * r), -v_free * gamma / ao_max * pm


def power_law_speed(ao: ArrayLike, v_free: float, ao_max: float, gamma: float) -> np.ndarray:
    """One class's eq. (3) speed V (1 - (AO / AO_max)^gamma), m/s, AO clipped at 0: the
    power law with its parameters as arguments (fitting one class, drawing a curve)."""
    return _power_speed(v_free, ao_max, gamma, np.maximum(np.asarray(ao, float), 0.0))


def _newell_terms(v_free: float, w: float, ao_jam: float, n: float,
                  ao: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The smoothed Newell speed V (1 + r^n)^(-1/n), r = V AO / (w (AO_jam - AO)), and its
    slope -V r^(n-1) (1 + r^n)^(-1/n-1) dr/dAO (module docstring); finite on
    [0, AO_jam)."""
    gap = ao_jam - ao
    r = v_free * ao / (w * gap)
    rn1 = _power(r, n - 1.0)
    base = 1.0 + rn1 * r
    shrink = base ** (-1.0 / n)
    return v_free * shrink, -v_free * rn1 * shrink / base * (v_free * ao_jam / (w * gap * gap))


def _newell_speed(v_free: float, w: float, ao_jam: float, n: float,
                  ao: np.ndarray) -> np.ndarray:
    return _newell_terms(v_free, w, ao_jam, n, ao)[0]


def _class_args(p: ModelParameters) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The HV's and the AV's arguments of the family's per-class functions, without AO."""
    if p.family == "power":
        return ((p.v_free_h, p.ao_max_h, p.gamma_h), (p.v_free_a, p.ao_max_a, p.gamma_a))
    return ((p.v_free_h, p.wave_speed_h, p.ao_max_h, p.corner),
            (p.v_free_a, p.wave_speed_a, p.ao_max_a, p.corner))


Speed = Callable[..., np.ndarray]
Terms = Callable[..., tuple[np.ndarray, np.ndarray]]
#: family -> (speed, speed and slope), each f(*class arguments, AO); the slope is defined
#: once per family, in its second function
_FAMILY: dict[str, tuple[Speed, Terms]] = {
    "power": (_power_speed, _power_terms), "newell": (_newell_speed, _newell_terms)}


def speed_of_ao(p: ModelParameters, ao: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(Ve_h(AO), Ve_a(AO)) in m/s for the family ``p.family`` (a Python float in, floats
    out: the twin's inlet asks for one state every step)."""
    if not isinstance(ao, float):
        ao = np.asarray(ao, float)
    speed, (h, a) = _FAMILY[p.family][0], _class_args(p)
    return speed(*h, ao), speed(*a, ao)


def speed_terms_of_ao(p: ModelParameters, ao: ArrayLike) -> SpeedTerms:
    """(Ve_h, Ve_a, dVe_h/dAO, dVe_a/dAO) at ``ao`` (> 0), sharing each class's powers:
    what the twin's flux needs every step."""
    ao = np.asarray(ao, float)
    terms, (h, a) = _FAMILY[p.family][1], _class_args(p)
    ve_h, d_h = terms(*h, ao)
    ve_a, d_a = terms(*a, ao)
    return ve_h, ve_a, d_h, d_a


def equilibrium_speeds(p: ModelParameters, rho_h: ArrayLike,
                       rho_a: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(Ve_h, Ve_a) in m/s at the given class densities (veh/m)."""
    return speed_of_ao(p, area_occupancy(p, rho_h, rho_a))


def speed_jacobian(p: ModelParameters, rho_h: ArrayLike, rho_a: ArrayLike) -> np.ndarray:
    """Partial derivatives of the equilibrium speeds, shape (..., 2, 2), in (m/s)/(veh/m).

    ``out[..., i, j] = dVe_i / drho_j`` with i, j in (h, a). Because Ve_i depends on the
    densities only through AO, ``dVe_i/drho_j = Ve_i'(AO) a_j / W``: the matrix has rank one.
    """
    _, _, d_h, d_a = speed_terms_of_ao(p, area_occupancy(p, rho_h, rho_a))
    slope = np.stack([d_h, d_a], axis=-1)[..., :, None]            # Ve_i'(AO)
    area = np.array([p.area_h, p.area_a])[None, :] / p.road_width  # a_j / W
    return slope * area
