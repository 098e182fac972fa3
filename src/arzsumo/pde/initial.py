"""Initial conditions of section 5, as primitive fields (rho_h, v_h, rho_a, v_a) on cell
centres (docs/twin.md, "Initial conditions").

Kinds: ``equilibrium`` (uniform); ``sinusoid``, stop-and-go z_k* (1 + A_k sin(2 pi n_k x / L
+ phi_k)) per variable k (the paper states no amplitude; default 10 %, two periods);
``nonrecurrent``, rho_i* (1 + f sin(pi x / L)) and v_i* (1 - f sin(pi x / L)); ``linear``,
the evident intent of the printed lane-closure profile, rho_i* (1 + f x / L) and
v_i* (1 - f x / L); ``random``, a seeded wave z_k* (1 + A_k g(x)) with g = sum_m c_m
sin(2 pi m x / L + phi_m) over modes m = 1..M, c_m ~ N(0, 1/m), phi_m ~ U(0, 2 pi),
normalised to max |g| = 1; ``array``, given fields (e.g. aggregated SUMO data).
:func:`initial_fields` refuses a profile outside the physical domain (the paper's f = 1/4
is, on ``paper_base``) and states the largest feasible fraction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from arzsumo.errors import ModelError, require
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.pde.state import domain_violation, to_conserved

KINDS = ("equilibrium", "sinusoid", "nonrecurrent", "linear", "random", "array")


def _four(name: str, value: object) -> tuple[float, ...]:
    arr = np.broadcast_to(np.asarray(value, float), (4,))
    require(bool(np.all(np.isfinite(arr))), name, value, "4 finite numbers (or one)")
    return tuple(float(v) for v in arr)


@dataclass(frozen=True)
class InitialCondition:
    """An initial profile; see the module docstring for the kinds.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    amplitude : float or 4 floats
        ``sinusoid``: relative amplitudes of (rho_h, v_h, rho_a, v_a) (fractions of the
        equilibrium values). ``nonrecurrent`` / ``linear``: the fraction f (first entry).
    wavenumber : float or 4 floats
        ``sinusoid``: periods over the road n_k, dimensionless. ``random``: the highest
        mode M (first entry, an integer).
    phase : float or 4 floats
        ``sinusoid``: phases phi_k, rad.
    seed : int
        ``random``: seed of the random shape.
    fields : tuple of 4 arrays, optional
        ``array``: (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) on the cell centres.
    """

    kind: str = "sinusoid"
    amplitude: tuple[float, ...] = (0.1, -0.1, 0.1, -0.1)
    wavenumber: tuple[float, ...] = (2.0, 2.0, 2.0, 2.0)
    phase: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)
    seed: int = 0
    fields: tuple[np.ndarray, ...] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        require(self.kind in KINDS, "kind", self.kind, f"one of {', '.join(KINDS)}")
        object.__setattr__(self, "amplitude", _four("amplitude", self.amplitude))
        object.__setattr__(self, "wavenumber", _four("wavenumber", self.wavenumber))
        object.__setattr__(self, "phase", _four("phase", self.phase))
        if self.kind == "array":
            require(self.fields is not None and len(self.fields) == 4, "fields",
                    None if self.fields is None else len(self.fields),
                    "4 arrays (rho_h, v_h, rho_a, v_a) for kind 'array'")
        if self.kind == "random":
            n = self.wavenumber[0]
            require(n == int(n) and 1 <= n <= 64, "wavenumber", n,
                    "an integer in 1..64 (the highest mode of the random wave)")
        require(isinstance(self.seed, int) and not isinstance(self.seed, bool)
                and self.seed >= 0, "seed", self.seed, "an integer >= 0")
        if self.kind in ("nonrecurrent", "linear"):
            require(-1.0 < self.amplitude[0] < 1.0, "amplitude", self.amplitude[0],
                    "a fraction f in (-1, 1)")


def _profile(ic: InitialCondition, x: np.ndarray, length: float) -> np.ndarray:
    """Relative perturbation shapes, shape (4, n): z = z* (1 + shape)."""
    s = x / length
    if ic.kind == "equilibrium":
        return np.zeros((4, x.size))
    if ic.kind == "sinusoid":
        a, n, ph = (np.asarray(v)[:, None] for v in (ic.amplitude, ic.wavenumber, ic.phase))
        return a * np.sin(2.0 * math.pi * n * s[None, :] + ph)
    if ic.kind == "random":
        rng = np.random.default_rng(ic.seed)
        m = np.arange(1, int(ic.wavenumber[0]) + 1, dtype=float)
        coef = rng.normal(0.0, 1.0 / m)
        phase = rng.uniform(0.0, 2.0 * math.pi, size=m.size)
        g = coef @ np.sin(2.0 * math.pi * m[:, None] * s[None, :] + phase[:, None])
        return np.asarray(ic.amplitude)[:, None] * (g / np.max(np.abs(g)))[None, :]
    f = ic.amplitude[0]
    base = np.sin(math.pi * s) if ic.kind == "nonrecurrent" else s
    return np.stack([f * base, -f * base, f * base, -f * base])


def initial_fields(ic: InitialCondition, eq: Equilibrium, x: np.ndarray) -> np.ndarray:
    """Primitive fields (rho_h, v_h, rho_a, v_a), shape (4, n), on cell centres ``x`` (m).

    Raises :class:`ModelError` naming the variable, value and position if the profile leaves
    the physical domain (negative density, AO >= AO_max, ...).
    """
    x = np.asarray(x, float)
    p = eq.params
    if ic.kind == "array":
        prim = np.stack([np.asarray(f, float) for f in ic.fields])  # type: ignore[union-attr]
        require(prim.shape == (4, x.size), "fields", prim.shape,
                f"4 arrays of {x.size} values (one per cell)")
    else:
        star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
        prim = star * (1.0 + _profile(ic, x, p.length))
    problem = domain_violation(p, to_conserved(p, *prim), x)
    if problem is not None:
        hint = ""
        if ic.kind in ("nonrecurrent", "linear"):
            f_max = p.ao_max / eq.ao - 1.0
            hint = f"; the largest feasible fraction here is f < {f_max:.3f}"
        raise ModelError(f"initial condition {ic.kind!r} leaves the physical domain: "
                         f"{problem}{hint}")
    return prim
