"""Unit conversions: the one place where km/h, veh/km and veh/h meet SI.

Inside arzsumo every quantity is SI: metres, seconds, veh/m, m/s, veh/s. Human units
appear only in scenario files, reports and plots, and they pass through these functions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

KMH_PER_MS = 3.6
VEH_KM_PER_VEH_M = 1000.0
#: seconds per hour: a time (or a vehicle time, veh s) in hours
S_PER_H = 3600.0
VEH_H_PER_VEH_S = S_PER_H


def kmh_to_ms(v: ArrayLike) -> np.ndarray | float:
    """Speed from km/h to m/s."""
    return np.asarray(v, dtype=float) / KMH_PER_MS if np.ndim(v) else float(v) / KMH_PER_MS


def ms_to_kmh(v: ArrayLike) -> np.ndarray | float:
    """Speed from m/s to km/h."""
    return np.asarray(v, dtype=float) * KMH_PER_MS if np.ndim(v) else float(v) * KMH_PER_MS


def veh_km_to_veh_m(rho: ArrayLike) -> np.ndarray | float:
    """Density from veh/km to veh/m."""
    return (np.asarray(rho, dtype=float) if np.ndim(rho) else float(rho)) / VEH_KM_PER_VEH_M


def veh_m_to_veh_km(rho: ArrayLike) -> np.ndarray | float:
    """Density from veh/m to veh/km."""
    return (np.asarray(rho, dtype=float) if np.ndim(rho) else float(rho)) * VEH_KM_PER_VEH_M


def veh_h_to_veh_s(q: ArrayLike) -> np.ndarray | float:
    """Flow from veh/h to veh/s."""
    return (np.asarray(q, dtype=float) if np.ndim(q) else float(q)) / VEH_H_PER_VEH_S


def veh_s_to_veh_h(q: ArrayLike) -> np.ndarray | float:
    """Flow from veh/s to veh/h."""
    return (np.asarray(q, dtype=float) if np.ndim(q) else float(q)) * VEH_H_PER_VEH_S


def s_to_h(t: ArrayLike) -> np.ndarray | float:
    """A time (or a vehicle time: veh s to veh h) from seconds to hours."""
    return (np.asarray(t, dtype=float) if np.ndim(t) else float(t)) / S_PER_H


def ms2_to_kmh2(p: ArrayLike) -> np.ndarray | float:
    """A squared speed (a variance or spectral power) from (m/s)^2 to (km/h)^2."""
    return (np.asarray(p, dtype=float) if np.ndim(p) else float(p)) * KMH_PER_MS ** 2


def per_m_to_per_km(g: ArrayLike) -> np.ndarray | float:
    """A rate along the road from 1/m to 1/km."""
    return (np.asarray(g, dtype=float) if np.ndim(g) else float(g)) * 1000.0
