"""Ensemble Kalman filter on the PDE twin (stochastic EnKF with perturbed observations).

Every control period the M first-order twins (:class:`BatchStepper`) are advanced with the
period's boundary data, each member with its own draw of the boundary noise, given additive
model-error noise, then updated with the period's loop and probe data (Evensen 1994;
Burgers, van Leeuwen & Evensen 1998; Houtekamer & Mitchell 2001)::

    X^f <- X^f + eta_k,  eta_k ~ N(0, diag(s)^2 C)         model error, per forecast
    X^f <- mean + lambda (X^f - mean)                     multiplicative inflation
    K   = (rho_xo o P H^T) (rho_oo o H P H^T + R)^-1      localised gain
    X^a = X^f + K (y + eps_k - h(X^f_k)),  eps_k ~ N(0, R)

The analysed state is the stacked primitive fields (rho_h, v_h, rho_a, v_a) on the cells;
P H^T and H P H^T are ensemble covariances; h interpolates a member's fields (or its class
flows rho_i v_i) linearly at the sensors; s is the per-variable model-error sd
(:attr:`EnkfOptions.model_sd`) and C a Gaussian correlation over
:attr:`EnkfOptions.model_length` (how they were chosen:
research/readings/enkf_model_noise.md); rho is the Gaspari & Cohn (1999) taper of the
distance, half-width :attr:`EnkfOptions.localisation`; R is diagonal from the records'
noise models. After each analysis the members are projected onto the physical domain
(:func:`arzsumo.estimate.batch.project`). Observations: loop densities, speeds (taken as
the field's speed at the station) and flows per class, probe speeds of their class.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import require
from arzsumo.estimate.batch import BatchStepper, project
from arzsumo.estimate.observations import Estimate, LoopObservation, ProbeObservation
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.model.params import ModelParameters
from arzsumo.pde.flux import FLUXES
from arzsumo.pde.state import to_conserved, to_primitive


@dataclass(frozen=True)
class EnkfOptions:
    """Settings of the ensemble Kalman filter (SI).

    Parameters
    ----------
    members : int
        Ensemble size M (>= 2).
    cells : int
        Cells of the ensemble's twins on [0, L] (the controller's grid).
    flux : {"hll", "rusanov"}
    cfl : float
        Target Courant number of the batched first-order scheme.
    inflation : float
        Multiplicative inflation lambda >= 1 of the forecast anomalies, per analysis.
    localisation : float
        Gaspari-Cohn half-width c, m (correlations vanish beyond 2c); inf: none.
    initial_sd : tuple of 4 floats
        Initial ensemble spread of (rho_h, v_h, rho_a, v_a) relative to the initial
        fields, smooth in space (correlation length ``initial_length`` m).
    initial_length : float
        Correlation length of the initial perturbations, m.
    rho_min : float
        Smallest density kept, veh/m.
    ao_fraction : float
        Largest AO kept, as a fraction of AO_max.
    seed : int
        Seed of the filter's random draws (initial ensemble, boundary and obs noise).
    model_sd : tuple of 4 floats
        Additive model-error noise per forecast (control period), absolute: standard
        deviations of (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s); 0: none (a perfect
        model, as in the synthetic twin experiments).
    model_length : float
        Correlation length in space of the model-error noise, m.
    """

    members: int = 32
    cells: int = 20
    flux: str = "hll"
    cfl: float = 0.9
    inflation: float = 1.05
    localisation: float = 150.0
    initial_sd: tuple[float, float, float, float] = (0.1, 0.1, 0.1, 0.1)
    initial_length: float = 150.0
    rho_min: float = 1e-4
    ao_fraction: float = 0.98
    seed: int = 0
    model_sd: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    model_length: float = 150.0

    def __post_init__(self) -> None:
        require(isinstance(self.members, int) and self.members >= 2, "members", self.members,
                "an integer >= 2")
        require(isinstance(self.cells, int) and self.cells >= 4, "cells", self.cells,
                "an integer >= 4")
        require(self.flux in FLUXES, "flux", self.flux, f"one of {', '.join(FLUXES)}")
        require(0 < self.cfl <= 1, "cfl", self.cfl, "a number in (0, 1]")
        require(self.inflation >= 1, "inflation", self.inflation, "a factor >= 1")
        require(self.localisation > 0, "localisation", self.localisation,
                "a distance > 0 m (inf: none)")
        require(len(self.initial_sd) == 4 and min(self.initial_sd) >= 0, "initial_sd",
                self.initial_sd, "4 relative spreads >= 0")
        require(0 < self.ao_fraction < 1, "ao_fraction", self.ao_fraction, "a fraction in (0, 1)")
        require(len(self.model_sd) == 4 and min(self.model_sd) >= 0
                and all(math.isfinite(v) for v in self.model_sd), "model_sd", self.model_sd,
                "4 standard deviations >= 0 (SI)")
        require(math.isfinite(self.model_length) and self.model_length > 0, "model_length",
                self.model_length, "a length > 0 m")


@dataclass(frozen=True)
class BoundaryInput:
    """Boundary data of one period for the ensemble, with their noise.

    Parameters
    ----------
    ghost : array (4,)
        Inlet ghost state (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) at x = 0.
    ghost_sd : array (4,)
        Standard deviations of its errors (same units); each member draws its own.
    outflow : float
        Outflow through x = L, veh/s (q* + U as the bridge's twins take it).
    outflow_sd : float
        Standard deviation of its error, veh/s.
    """

    ghost: np.ndarray
    ghost_sd: np.ndarray
    outflow: float
    outflow_sd: float

    @classmethod
    def from_loops(cls, p: ModelParameters, loops: LoopObservation) -> BoundaryInput:
        """From stations at both ends: the first gives the ghost state (a class speed
        missing there is its equilibrium speed), the last the outflow (sum of classes)."""
        rho = loops.density[:, 0]
        ve = equilibrium_speeds(p, rho[0], rho[1])
        v = np.where(np.isfinite(loops.speed[:, 0]), loops.speed[:, 0], ve)
        n = loops.noise
        return cls(np.array([rho[0], v[0], rho[1], v[1]]),
                   np.array([n.density, n.speed, n.density, n.speed]),
                   float(loops.flow[:, -1].sum()), math.sqrt(2.0) * n.flow)


def gaspari_cohn(d: np.ndarray, c: float) -> np.ndarray:
    """Gaspari & Cohn (1999) eq. (4.10) taper of distances ``d`` (m), half-width ``c``."""
    r = np.abs(np.asarray(d, float)) / c
    with np.errstate(divide="ignore", invalid="ignore"):
        inner = ((-0.25 * r + 0.5) * r + 0.625) * r ** 3 - 5.0 / 3.0 * r ** 2 + 1.0
        outer = ((((r / 12.0 - 0.5) * r + 0.625) * r + 5.0 / 3.0) * r - 5.0) * r + 4.0 \
            - 2.0 / (3.0 * r)
    return np.where(r <= 1.0, inner, np.where(r < 2.0, outer, 0.0))


@dataclass(frozen=True)
class _Obs:
    """Scalar observations: position x (m), field index (0-3 primitive, 4-5 class flow),
    value and error sd, all (m,)."""

    x: np.ndarray
    kind: np.ndarray
    y: np.ndarray
    sd: np.ndarray


def _stack_obs(loops: Sequence[LoopObservation], probes: Sequence[ProbeObservation]) -> _Obs:
    """All finite scalar data of the records, as :class:`_Obs`."""
    xs, kinds, ys, sds = [], [], [], []

    def add(x: np.ndarray, kind: int, y: np.ndarray, sd: float) -> None:
        ok = np.isfinite(y)
        xs.append(x[ok])
        kinds.append(np.full(int(ok.sum()), kind))
        ys.append(y[ok])
        sds.append(np.full(int(ok.sum()), sd))

    for obs in loops:
        for i in range(2):
            add(obs.x, 2 * i, obs.density[i], obs.noise.density)
            add(obs.x, 2 * i + 1, obs.speed[i], obs.noise.speed)
            add(obs.x, 4 + i, obs.flow[i], obs.noise.flow)
    for pr in probes:
        add(pr.x, 2 * pr.index + 1, pr.v, pr.noise.speed)
    if not xs:
        return _Obs(np.empty(0), np.empty(0, int), np.empty(0), np.empty(0))
    return _Obs(np.concatenate(xs), np.concatenate(kinds).astype(int), np.concatenate(ys),
                np.concatenate(sds))


def smooth_noise(x: np.ndarray, length: float, shape: tuple[int, ...],
                 rng: np.random.Generator) -> np.ndarray:
    """Gaussian noise of unit variance on ``x`` (last axis), Gaussian-correlated over
    ``length`` m; ``shape`` is the leading shape."""
    d = x[:, None] - x[None, :]
    w = np.exp(-0.5 * (d / length) ** 2)
    w /= np.sqrt((w ** 2).sum(axis=1, keepdims=True))
    return rng.standard_normal((*shape, x.size)) @ w.T


class EnsembleKalmanFilter:
    """Stochastic EnKF on a batch of first-order twins; see the module docstring.

    Parameters
    ----------
    params : ModelParameters
    initial : array (4, cells)
        First guess of (rho_h, v_h, rho_a, v_a) on the cells (e.g. the equilibrium).
    options : EnkfOptions, optional
    t0 : float
        Time of the first guess, s.

    Attributes
    ----------
    q : ndarray (4, M, cells)
        Conserved states of the members.
    t : float
        Time of the ensemble, s.
    """

    def __init__(self, params: ModelParameters, initial: np.ndarray,
                 options: EnkfOptions | None = None, t0: float = 0.0) -> None:
        self.p = params
        self.options = o = options or EnkfOptions()
        self.stepper = BatchStepper(params, o.cells, o.flux, o.cfl)
        self.x = self.stepper.x
        self.rng = np.random.default_rng(o.seed)
        initial = np.asarray(initial, float)
        require(initial.shape == (4, o.cells), "initial", initial.shape,
                f"shape (4, {o.cells}) of (rho_h, v_h, rho_a, v_a) on the cells")
        sd = np.asarray(o.initial_sd)[:, None, None] * initial[:, None, :]
        z = initial[:, None, :] + sd * smooth_noise(self.x, o.initial_length,
                                                    (4, o.members), self.rng)
        self.q = self._conserved(z)
        self.t = float(t0)
        self._state_x = np.tile(self.x, 4)            # positions of the stacked state

    def _conserved(self, z: np.ndarray) -> np.ndarray:
        o = self.options
        return to_conserved(self.p, *project(self.p, z, o.rho_min, o.ao_fraction))

    def primitive(self) -> np.ndarray:
        """Members' fields (4, M, cells): rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s."""
        return to_primitive(self.p, self.q)

    def estimate(self) -> Estimate:
        """Ensemble mean and spread (sample sd) of the primitive fields now."""
        z = self.primitive()
        return Estimate(self.t, self.x, z.mean(axis=1), z.std(axis=1, ddof=1))

    def forecast(self, t_end: float, boundary: BoundaryInput) -> None:
        """Advance every member to ``t_end`` (s) with its own draw of the boundary data."""
        m = self.options.members
        ghost = boundary.ghost[:, None] + boundary.ghost_sd[:, None] * \
            self.rng.standard_normal((4, m))
        ghost = project(self.p, ghost, self.options.rho_min, self.options.ao_fraction)
        outflow = np.maximum(boundary.outflow + boundary.outflow_sd
                             * self.rng.standard_normal(m), 0.0)
        self.q, self.t, _ = self.stepper.advance(self.q, self.t, t_end, ghost, outflow,
                                                 self.stepper.last_speed)
        sd = np.asarray(self.options.model_sd, float)
        if sd.any():
            z = self.primitive() + sd[:, None, None] * smooth_noise(
                self.x, self.options.model_length, (4, m), self.rng)
            self.q = self._conserved(z)

    def analyse(self, loops: Sequence[LoopObservation] = (),
                probes: Sequence[ProbeObservation] = ()) -> None:
        """Update the members with the records (inflation, localised perturbed-obs EnKF)."""
        obs = _stack_obs(loops, probes)
        o = self.options
        z = self.primitive()
        mean = z.mean(axis=1, keepdims=True)
        z = project(self.p, mean + o.inflation * (z - mean), o.rho_min, o.ao_fraction)
        if obs.y.size:
            z = self._update(z, obs)
        self.q = self._conserved(z)

    def _update(self, z: np.ndarray, obs: _Obs) -> np.ndarray:
        """The localised stochastic EnKF update of primitive members ``z`` (4, M, n)."""
        o, m = self.options, self.options.members
        hx = self._observe(z, obs)                                 # (n_obs, M)
        xs = z.transpose(0, 2, 1).reshape(-1, m)                   # (4 n, M)
        a = xs - xs.mean(axis=1, keepdims=True)
        ha = hx - hx.mean(axis=1, keepdims=True)
        pht = a @ ha.T / (m - 1)
        hpht = ha @ ha.T / (m - 1)
        if math.isfinite(o.localisation):
            pht *= gaspari_cohn(self._state_x[:, None] - obs.x[None, :], o.localisation)
            hpht *= gaspari_cohn(obs.x[:, None] - obs.x[None, :], o.localisation)
        s = hpht + np.diag(obs.sd ** 2)
        d = obs.y[:, None] + obs.sd[:, None] * self.rng.standard_normal(hx.shape) - hx
        xs = xs + pht @ np.linalg.solve(s, d)
        return xs.reshape(4, -1, m).transpose(0, 2, 1)

    def _observe(self, z: np.ndarray, obs: _Obs) -> np.ndarray:
        """h(z): member fields (or class flows) interpolated at the sensors, (n_obs, M)."""
        fields = np.concatenate([z, z[[0, 2]] * z[[1, 3]]])        # (6, M, n)
        x, dx = self.x, self.stepper.dx
        i1 = np.clip(np.searchsorted(x, obs.x), 1, x.size - 1)
        i0 = i1 - 1
        f = np.clip((obs.x - x[i0]) / dx, 0.0, 1.0)[:, None]
        return (1.0 - f) * fields[obs.kind, :, i0] + f * fields[obs.kind, :, i1]

    def step(self, t_end: float, boundary: BoundaryInput,
             loops: Sequence[LoopObservation] = (),
             probes: Sequence[ProbeObservation] = ()) -> Estimate:
        """One control period: :meth:`forecast` to ``t_end``, :meth:`analyse`, estimate."""
        self.forecast(t_end, boundary)
        self.analyse(loops, probes)
        return self.estimate()
