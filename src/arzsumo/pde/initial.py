"""Initial conditions of section 5 ("Simulation settings" and "Experiments with different
initial traffic conditions"), as primitive fields (rho_h, v_h, rho_a, v_a) on cell centres.

Kinds
-----
``equilibrium``
    The uniform equilibrium.
``sinusoid``
    Stop-and-go: z_k(x, 0) = z_k* (1 + A_k sin(2 pi n_k x / L + phi_k)) for each of the
    four variables k, with relative amplitude A_k and n_k periods over the road (spatial
    wavenumber 2 pi n_k / L). Opposite signs for density and speed give stop-and-go
    (dense and slow, then sparse and fast). The paper states no amplitude; the default is
    10 %, two periods.
``nonrecurrent``
    The paper's non-recurrent profile: rho_i* (1 + f sin(pi x / L)), v_i* (1 - f sin(pi x /
    L)), f = 1/4 as printed.
``linear``
    The lane-closure profile. As printed, rho_i(x, 0) = rho_i* x / 4 and v_i(x, 0) =
    -v_i* x / 4 are dimensionally broken (density times metres; negative speeds; zero
    density at the inlet, against the inlet condition). We implement the evident intent,
    a perturbation growing linearly from zero at x = 0 to a fraction f of the equilibrium
    at x = L: rho_i* (1 + f x / L), v_i* (1 - f x / L), f = 1/4 by default.
``random``
    A seeded stop-and-go wave: one random smooth shape g(x) = sum_m c_m sin(2 pi m x / L +
    phi_m) over modes m = 1..M (M the wavenumber: at most M periods over the road),
    normalised to max |g| = 1, then z_k* (1 + A_k g(x)). The amplitudes keep the
    sinusoid's sign structure (dense where slow); the seed draws the coefficients
    c_m ~ N(0, 1/m) and phases phi_m ~ U(0, 2 pi). Gives sweeps over seeds a spread of
    initial waves where the paper's profiles are deterministic.
``array``
    Arbitrary fields (e.g. aggregated SUMO data) given as arrays on the cell centres.

Note: with f = 1/4 both densities rise by 25 %, which on ``paper_base`` (AO* = 0.709) gives
AO = 0.887, above AO_max = 0.85: the paper's printed amplitudes are outside the physical
domain of this fundamental diagram. :func:`initial_fields` refuses such profiles and
states the largest feasible fraction.
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

    @classmethod
    def paper(cls, kind: str, fraction: float = 0.25) -> InitialCondition:
        """The paper's ``nonrecurrent`` or ``linear`` profile with fraction f."""
        return cls(kind=kind, amplitude=fraction)


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

    Raises
    ------
    ModelError
        If the profile leaves the physical domain (negative density, AO >= AO_max, ...);
        the message names the variable, value and position.
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
    if np.any(prim[[0, 2]] <= 0):
        raise ModelError(f"initial condition {ic.kind!r}: densities must be > 0 "
                         "(the twin divides by rho_i)")
    return prim
