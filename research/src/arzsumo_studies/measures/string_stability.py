"""Linear string stability of a car-following model: the theory beside the measured growth.

A time-continuous car-following model gives the acceleration f(s, v, dv) of a vehicle
from its net gap s (m), its speed v (m/s) and dv = v_lead - v (m/s). Linearised about a
stationary platoon (all vehicles at speed v and gap s, dv = 0), a leader's oscillation of
angular frequency omega reaches its follower multiplied by

    G(omega) = (f_s + i omega f_dv) / (f_s - omega^2 + i omega (f_dv - f_v)),

with the partial derivatives f_s = df/ds > 0, f_v = df/dv < 0 and f_dv = df/d(dv) >= 0
(Treiber & Kesting, *Traffic Flow Dynamics*, ch. 15). |G(0)| = 1; the platoon is string
stable when |G| <= 1 at every frequency, which holds iff

    f_v^2 / 2 - f_dv f_v - f_s >= 0.

An oscillation then grows over N followers by at most max|G|^N. For the optimal-velocity
model f = kappa (V(s) - v) this is Bando et al.'s (1995) V'(s) <= kappa / 2.

:func:`idm_partials` gives IDM's derivatives (Treiber, Hennecke & Helbing 2000), with
s*(v, dv) = s0 + v T - v dv / (2 sqrt(a b)) and f = a (1 - (v / v0)^delta - (s* / s)^2).
SI units throughout; pure functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import require


@dataclass(frozen=True)
class Partials:
    """f_s (1/s^2), f_v (1/s) and f_dv (1/s) of a car-following model at a state."""

    f_s: float
    f_v: float
    f_dv: float

    def __post_init__(self) -> None:
        require(math.isfinite(self.f_s) and self.f_s > 0, "f_s", self.f_s,
                "> 0 (more gap, more acceleration)")
        require(math.isfinite(self.f_v) and self.f_v < 0, "f_v", self.f_v,
                "< 0 (faster, less acceleration)")
        require(math.isfinite(self.f_dv) and self.f_dv >= 0, "f_dv", self.f_dv,
                ">= 0 (a faster leader, more acceleration)")

    @property
    def criterion(self) -> float:
        """f_v^2 / 2 - f_dv f_v - f_s, 1/s^2: >= 0 iff string stable."""
        return self.f_v ** 2 / 2 - self.f_dv * self.f_v - self.f_s

    @property
    def stable(self) -> bool:
        """String stable (the criterion holds)."""
        return self.criterion >= 0.0


def string_gain(p: Partials, omega: np.ndarray) -> np.ndarray:
    """|G(omega)| at angular frequencies ``omega`` (rad/s)."""
    w = np.asarray(omega, float)
    num = p.f_s + 1j * w * p.f_dv
    den = p.f_s - w ** 2 + 1j * w * (p.f_dv - p.f_v)
    return np.abs(num / den)


def max_string_gain(p: Partials) -> tuple[float, float]:
    """(largest |G|, the angular frequency where it is, rad/s): (1, 0) when stable.

    With x = omega^2, a = f_s, b = f_dv, c = f_dv - f_v, |G|^2 = N / D with
    N = a^2 + b^2 x and D = (a - x)^2 + c^2 x. N' D - N D' = 0 reads
    -b^2 x^2 - 2 a^2 x + a^2 (b^2 + 2 a - c^2) = 0, whose constant term is -2 a^2 times
    the stability criterion: when it fails, the one positive root is the peak.
    """
    a, b, c = p.f_s, p.f_dv, p.f_dv - p.f_v
    q0 = a * a * (b * b + 2.0 * a - c * c)
    if q0 <= 0.0:
        return 1.0, 0.0
    x = q0 / (2.0 * a * a) if b == 0.0 else \
        (math.sqrt(a ** 4 + b * b * q0) - a * a) / (b * b)
    w = math.sqrt(x)
    return float(string_gain(p, np.array([w]))[0]), w


def growth_over(p: Partials, vehicles: float) -> float:
    """max|G|^N: the largest linear growth of an oscillation over N followers."""
    require(math.isfinite(vehicles) and vehicles >= 0, "vehicles", vehicles, ">= 0")
    return max_string_gain(p)[0] ** vehicles


@dataclass(frozen=True)
class IdmParameters:
    """IDM: a (m/s^2), b (m/s^2), T (s), s0 (m), v0 (m/s), delta."""

    a: float
    b: float
    T: float
    s0: float
    v0: float
    delta: float = 4.0

    def __post_init__(self) -> None:
        for name in ("a", "b", "T", "s0", "v0", "delta"):
            v = getattr(self, name)
            require(math.isfinite(v) and v > 0, name, v, "a finite number > 0")

    def equilibrium_gap(self, v: float) -> float:
        """The net gap (m) at which a vehicle at speed ``v`` (m/s) neither speeds up nor
        slows down behind a leader at the same speed."""
        require(0 <= v < self.v0, "v", v, f"a speed in [0, v0 = {self.v0:g}) m/s")
        return (self.s0 + v * self.T) / math.sqrt(1.0 - (v / self.v0) ** self.delta)


def idm_partials(p: IdmParameters, s: float, v: float) -> Partials:
    """IDM's f_s, f_v, f_dv at net gap ``s`` (m), speed ``v`` (m/s) and dv = 0."""
    require(s > 0 and v > 0, "(s, v)", (s, v), "a gap and a speed > 0")
    star = p.s0 + v * p.T
    f_s = 2.0 * p.a * star ** 2 / s ** 3
    f_v = -p.a * (p.delta * v ** (p.delta - 1.0) / p.v0 ** p.delta
                  + 2.0 * star * p.T / s ** 2)
    f_dv = p.a * star * v / (s ** 2 * math.sqrt(p.a * p.b))
    return Partials(f_s, f_v, f_dv)
