"""Sensor observations handed to the estimators: loop stations and probe vehicles (SI).

Two kinds of record, :class:`LoopObservation` and :class:`ProbeObservation`, each frozen,
validated on construction, with its own noise model: standard deviations of measurement
errors assumed Gaussian, unbiased and independent between quantities, stations, vehicles
and periods. Class index order everywhere: 0 = HV (h), 1 = AV (a). Nothing here reads SUMO.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.errors import require

#: Vehicle classes, in index order.
CLASSES = ("h", "a")


def _frozen(values: ArrayLike) -> np.ndarray:
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr


def _sd(name: str, value: float) -> None:
    require(isinstance(value, int | float) and math.isfinite(value) and value > 0, name,
            value, "a standard deviation > 0")


@dataclass(frozen=True)
class LoopNoise:
    """Measurement-error standard deviations of a loop station, per period and class, of
    the count-based flow (veh/s), the loop speed (time-mean or harmonic, m/s) and the density
    (from occupancy, veh/m)."""

    flow: float = 0.1
    speed: float = 1.5
    density: float = 0.008

    def __post_init__(self) -> None:
        for name in ("flow", "speed", "density"):
            _sd(name, getattr(self, name))


@dataclass(frozen=True)
class ProbeNoise:
    """Measurement-error standard deviation of a probe's speed, m/s (positions exact)."""

    speed: float = 1.0

    def __post_init__(self) -> None:
        _sd("speed", self.speed)


@dataclass(frozen=True)
class LoopObservation:
    """One period of data from loop stations at ``x`` (m), per class.

    Parameters
    ----------
    t : float
        End of the counting period, s.
    period : float
        Length of the counting period, s (the data describe [t - period, t]).
    x : array (n_j,)
        Station positions, m, increasing.
    flow, speed, density : array (2, n_j)
        Per class (h, a): count-based flow veh/s, speed m/s (NaN: no vehicle of the class
        passed; the time-mean or the harmonic mean of the spot speeds, per ``[sensing]
        loop_speed``), density veh/m (from the occupancy, :func:`density_from_occupancy`).
        ``speed`` is what the estimators use.
    noise : LoopNoise
    time_mean, harmonic : array (2, n_j), optional
        Both means of the same spot speeds, m/s, when the reader has them (SUMO's loops,
        :mod:`arzsumo.sumo.loops`; ``speed`` is one of them): an offline pass over a
        recorded run can use either (:mod:`arzsumo_studies.estimation.sensor_record`).
    """

    t: float
    period: float
    x: np.ndarray
    flow: np.ndarray
    speed: np.ndarray
    density: np.ndarray
    noise: LoopNoise = LoopNoise()
    time_mean: np.ndarray | None = None
    harmonic: np.ndarray | None = None

    def __post_init__(self) -> None:
        require(math.isfinite(self.t), "t", self.t, "a finite time in s")
        require(math.isfinite(self.period) and self.period > 0, "period", self.period,
                "a time > 0 s")
        x = _frozen(self.x)
        require(x.ndim == 1 and x.size >= 1 and bool(np.all(np.isfinite(x)))
                and bool(np.all(np.diff(x) > 0)), "x", self.x,
                "station positions in m, finite and increasing")
        object.__setattr__(self, "x", x)
        for name in ("flow", "speed", "density", "time_mean", "harmonic"):
            if getattr(self, name) is None:
                continue
            arr = _frozen(getattr(self, name))
            require(arr.shape == (2, x.size), name, arr.shape,
                    f"shape (2, {x.size}): classes (h, a) by station")
            object.__setattr__(self, name, arr)
        require(bool(np.all(np.isfinite(self.flow)) and np.all(np.isfinite(self.density))),
                "flow/density", "not finite", "finite values (only speeds may be NaN)")

    @property
    def t_mid(self) -> float:
        """Middle of the counting period, s: the time the data stand for."""
        return self.t - 0.5 * self.period


@dataclass(frozen=True)
class ProbeObservation:
    """Positions and speeds of probe vehicles of one class at time ``t``.

    Parameters
    ----------
    t : float
        Time of the snapshot, s.
    cls : {"h", "a"}
        Vehicle class of the probes.
    x, v : array (n,)
        Positions (m) and speeds (m/s) of the probes (n may be 0).
    share : float
        Fraction of the class's vehicles that report, in (0, 1] (1: every AV is a probe).
    noise : ProbeNoise
    """

    t: float
    cls: str
    x: np.ndarray
    v: np.ndarray
    share: float = 1.0
    noise: ProbeNoise = ProbeNoise()

    def __post_init__(self) -> None:
        require(math.isfinite(self.t), "t", self.t, "a finite time in s")
        require(self.cls in CLASSES, "cls", self.cls, "h or a")
        require(0.0 < self.share <= 1.0, "share", self.share, "a fraction in (0, 1]")
        x, v = _frozen(self.x), _frozen(self.v)
        require(x.ndim == 1 and v.shape == x.shape, "x, v", (x.shape, v.shape),
                "two 1-D arrays of equal length")
        require(bool(np.all(np.isfinite(x)) and np.all(np.isfinite(v))), "x, v", "not finite",
                "finite positions (m) and speeds (m/s)")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "v", v)

    @property
    def index(self) -> int:
        """Class index (0 = h, 1 = a)."""
        return CLASSES.index(self.cls)


def density_from_occupancy(occupancy: ArrayLike, effective_length: float) -> np.ndarray:
    """Density rho = occupancy / (vehicle length + loop length), veh/m, from the time
    fraction ``occupancy`` in [0, 1] the loop was occupied and ``effective_length`` (m),
    the mean vehicle length plus the detection zone length."""
    _sd("effective_length", effective_length)
    return np.asarray(occupancy, float) / effective_length


@dataclass(frozen=True)
class Estimate:
    """An estimator's output at time ``t`` (s) on cell centres ``x`` (m).

    ``mean`` (4, n): (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s); ``sd`` (4, n): their
    uncertainty (ensemble spread) in the same units, or None where the method gives none.
    """

    t: float
    x: np.ndarray
    mean: np.ndarray
    sd: np.ndarray | None = None
