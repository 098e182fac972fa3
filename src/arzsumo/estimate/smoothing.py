"""Adaptive smoothing method (ASM) for detector and probe data, per class.

Treiber & Helbing (2002), "Reconstructing the spatio-temporal traffic dynamics from
stationary detector data", Cooperative Transportation Dynamics 1, 3.1-3.24; generalised
to heterogeneous data (several sources with their own errors) by Treiber, Kesting &
Wilson (2011), Comput.-Aided Civ. Infrastruct. Eng. 26, 408-419.

Each quantity z in (rho_h, v_h, rho_a, v_a) is estimated at (x, t) twice, by kernels
that spread data along the characteristic lines of free and of congested traffic::

    phi_c(dx, dt) = exp(-|dx| / sigma - |dt - dx / c| / tau),   dx = x - x_i, dt = t - t_i
    z_c(x, t) = sum_i beta_i phi_c z_i / sum_i beta_i phi_c,    c in {c_free, c_cong}

with beta_i = 1 / sd_i^2 the weight of data point i from its source's noise model (the
heterogeneous-data generalisation), and blended by the speed::

    w = (1 + tanh((V_crit - min(V_free, V_cong)) / dV)) / 2
    z = w z_cong + (1 - w) z_free

V_free, V_cong are the mixed space-mean speeds (q_h + q_a) / (rho_h + rho_a) of the two
estimates (the class speeds where a density is missing), so both classes share one
congestion weight: a congestion wave is a property of the whole stream. Loop stations
give densities and class speeds at the middle of their period; probes give class speeds.

Kernels are truncated at |t - t_i| > :attr:`AsmParameters.window` (data further away
weigh < e^-3 of a near one). ``causal=True`` uses only data with t_i <= t, for real
time; :class:`CausalSmoother` keeps that window of data and returns one row per period.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import require
from arzsumo.estimate.observations import LoopObservation, ProbeObservation
from arzsumo.units import kmh_to_ms

#: Kernel products per chunk of the vectorised sums (memory bound).
_CHUNK = 2_000_000


@dataclass(frozen=True)
class AsmParameters:
    """Parameters of the adaptive smoothing method (SI): the propagation speeds of
    perturbations in free flow ``c_free`` > 0 and in congestion ``c_cong`` < 0 (m/s), the
    smoothing widths in space ``sigma`` (m) and in time ``tau`` (s), the crossover speed
    ``v_crit`` between the two kernels and its width ``dv`` (m/s)."""

    c_free: float = float(kmh_to_ms(80.0))
    c_cong: float = float(kmh_to_ms(-15.0))
    sigma: float = 150.0
    tau: float = 15.0
    v_crit: float = float(kmh_to_ms(60.0))
    dv: float = float(kmh_to_ms(20.0))

    def __post_init__(self) -> None:
        for name in ("c_free", "sigma", "tau", "v_crit", "dv"):
            value = getattr(self, name)
            require(math.isfinite(value) and value > 0, name, value, "a number > 0 (SI)")
        require(math.isfinite(self.c_cong) and self.c_cong < 0, "c_cong", self.c_cong,
                "a negative speed in m/s (congestion waves travel upstream)")

    @property
    def window(self) -> float:
        """Largest |t - t_i| (s) that enters a kernel sum: 3 (tau + sigma / |c_cong|)."""
        return 3.0 * (self.tau + self.sigma / abs(self.c_cong))


@dataclass(frozen=True)
class DataPoints:
    """Data at N space-time points: positions x (m) and times t (s), (N,); values and
    weights 1/sd^2 of (rho_h, v_h, rho_a, v_a), (N, 4), weight 0 (value 0) where a point
    has no datum of that quantity. A loop station's period is one point with all four
    quantities, so the kernels are evaluated once for them."""

    x: np.ndarray
    t: np.ndarray
    value: np.ndarray
    weight: np.ndarray

    def select(self, keep: np.ndarray) -> DataPoints:
        """The points where ``keep`` is True."""
        return DataPoints(self.x[keep], self.t[keep], self.value[keep], self.weight[keep])

    @staticmethod
    def join(parts: Sequence[DataPoints]) -> DataPoints:
        """All points of ``parts``, in order."""
        if not parts:
            return DataPoints(np.empty(0), np.empty(0), np.empty((0, 4)), np.empty((0, 4)))
        return DataPoints(*(np.concatenate([getattr(p, f) for p in parts])
                            for f in ("x", "t", "value", "weight")))


def _loop_points(obs: LoopObservation) -> DataPoints:
    """One point per station: densities and speeds of both classes (NaN speeds: weight 0)."""
    n = obs.noise
    value = np.stack([obs.density[0], obs.speed[0], obs.density[1], obs.speed[1]], axis=1)
    sd = np.array([n.density, n.speed, n.density, n.speed])
    weight = np.where(np.isfinite(value), sd ** -2.0, 0.0)
    return DataPoints(obs.x, np.full(obs.x.size, obs.t_mid), np.nan_to_num(value), weight)


def _probe_points(pr: ProbeObservation, width: float) -> DataPoints:
    """Probe speeds averaged in bins of ``width`` m (0: one point per probe): one point
    per occupied bin, at the mean position of its probes, weighted by count / sd^2."""
    if width > 0:
        b = np.floor(pr.x / width).astype(int)
        b -= b.min(initial=0)
        n = np.bincount(b)
        occ = n > 0
        x, count = np.bincount(b, pr.x)[occ] / n[occ], n[occ]
        v = np.bincount(b, pr.v)[occ] / count
    else:
        x, v, count = pr.x, pr.v, np.ones(pr.x.size)
    value, weight = np.zeros((x.size, 4)), np.zeros((x.size, 4))
    k = 2 * pr.index + 1
    value[:, k], weight[:, k] = v, count / pr.noise.speed ** 2
    return DataPoints(x, np.full(x.size, pr.t), value, weight)


def data_points(loops: Sequence[LoopObservation] = (),
                probes: Sequence[ProbeObservation] = (),
                probe_bin: float = 50.0) -> DataPoints:
    """Flatten loop densities and speeds, and probe speeds, into :class:`DataPoints`.

    Probe speeds of one snapshot are first averaged in bins of ``probe_bin`` m (0: every
    probe is a point); the bin's weight is its count over sd^2, so the sums are nearly
    unchanged while their cost no longer grows with the number of probes.
    """
    return DataPoints.join([_loop_points(obs) for obs in loops]
                           + [_probe_points(pr, probe_bin) for pr in probes if pr.x.size])


def _sums(pts: DataPoints, xg: np.ndarray, tg: np.ndarray, c: float,
          par: AsmParameters, causal: bool) -> tuple[np.ndarray, np.ndarray]:
    """Kernel-weighted sums (G, 4) of beta z and of beta over the output points (G,)."""
    dx = xg[:, None] - pts.x[None, :]
    dt = tg[:, None] - pts.t[None, :]
    phi = np.exp(-np.abs(dx) / par.sigma - np.abs(dt - dx / c) / par.tau)
    if causal:
        phi[dt < 0.0] = 0.0
    return phi @ (pts.weight * pts.value), phi @ pts.weight


def _mixed_speed(z: np.ndarray) -> np.ndarray:
    """(q_h + q_a) / (rho_h + rho_a) of fields z (G, 4); class-speed mean where no density."""
    speeds = z[:, [1, 3]]
    known = np.isfinite(speeds).sum(axis=1)
    # NaN where neither class has a speed (np.nanmean would warn on such rows)
    class_mean = np.where(known > 0, np.nansum(speeds, axis=1) / np.maximum(known, 1), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        v = (z[:, 0] * z[:, 1] + z[:, 2] * z[:, 3]) / (z[:, 0] + z[:, 2])
    return np.where(np.isfinite(v), v, class_mean)


def _blend(free: np.ndarray, cong: np.ndarray, par: AsmParameters) -> np.ndarray:
    """w z_cong + (1 - w) z_free with the tanh weight on the mixed speed; NaN-tolerant."""
    with np.errstate(invalid="ignore"):
        vmin = np.fmin(_mixed_speed(free), _mixed_speed(cong))
    w = (0.5 * (1.0 + np.tanh((par.v_crit - vmin) / par.dv)))[:, None]
    out = w * cong + (1.0 - w) * free
    return np.where(np.isnan(free), cong, np.where(np.isnan(cong), free, out))


def smooth(points: DataPoints, x: np.ndarray, t: np.ndarray,
           params: AsmParameters | None = None, causal: bool = False) -> np.ndarray:
    """ASM fields (rho_h, v_h, rho_a, v_a) on the grid ``x`` (m) at times ``t`` (s).

    Parameters
    ----------
    points : DataPoints
        The data (:func:`data_points`).
    x, t : array
        Output positions (cell centres, m) and times (s).
    params : AsmParameters, optional
    causal : bool
        Use only data from t_i <= t (real time).

    Returns
    -------
    ndarray, shape (len(t), 4, len(x))
        Densities veh/m and speeds m/s; NaN where no datum of the quantity is in reach.
    """
    par = params or AsmParameters()
    x, t = np.asarray(x, float), np.atleast_1d(np.asarray(t, float))
    out = np.full((t.size, 4, x.size), np.nan)
    step = max(1, _CHUNK // max(1, x.size * max(points.x.size, 1)))
    for k in range(0, t.size, step):
        tk = t[k:k + step]
        hi = tk[-1] if causal else tk[-1] + par.window
        pts = points.select((points.t >= tk[0] - par.window) & (points.t <= hi))
        xg, tg = np.tile(x, tk.size), np.repeat(tk, x.size)
        est = []
        for c in (par.c_free, par.c_cong):
            num, den = _sums(pts, xg, tg, c, par, causal)
            with np.errstate(invalid="ignore", divide="ignore"):
                est.append(np.where(den > 1e-300, num / den, np.nan))
        out[k:k + step] = _blend(*est, par).reshape(tk.size, x.size, 4).transpose(0, 2, 1)
    return out


class CausalSmoother:
    """Real-time ASM on a fixed grid: add each period's data, estimate the present.

    ``x`` (m) are the output positions (the controller's cell centres); the data of the
    last :attr:`AsmParameters.window` seconds are kept.
    """

    def __init__(self, x: np.ndarray, params: AsmParameters | None = None) -> None:
        self.x = np.asarray(x, float)
        self.params = params or AsmParameters()
        self.points = DataPoints.join([])

    def add(self, loops: Sequence[LoopObservation] = (),
            probes: Sequence[ProbeObservation] = ()) -> None:
        """Store one period's loop and probe records."""
        self.points = DataPoints.join([self.points, data_points(loops, probes)])

    def estimate(self, t: float) -> np.ndarray:
        """Fields (4, n) at time ``t`` (s) from the data up to ``t``; older data dropped."""
        self.points = self.points.select(self.points.t >= t - self.params.window)
        return smooth(self.points, self.x, np.array([t]), self.params, causal=True)[0]
