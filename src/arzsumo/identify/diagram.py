"""Stage 1 of the identification: the fundamental diagram from stationary states.

As traffic practice does (Fan, Herty & Seibold 2014; Dervisoglu et al. 2009; the wave
speed from detector cross-correlation, Coifman & Wang 2005): :func:`block_states` gives
a run's Edie block states, per class; :func:`fit_diagram` fits a family's diagram
parameters to the block speeds and lambda_4 to the measured wave speed
(:class:`~arzsumo.identify.wave_target.WaveTarget`), with the parameters' 1-sigma from
the Jacobian and optionally a bootstrap over runs. ``docs/identify.md``, 'Two stages'.

Pure: arrays in, a frozen :class:`DiagramFit` out. SI: veh/m, m/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from arzsumo.errors import require
from arzsumo.identify.data import IdentifyError, ReplayData
from arzsumo.identify.objective import DEFAULT_BOUNDS
from arzsumo.identify.wave_target import INADMISSIBLE, WaveTarget
from arzsumo.model.fd import area_occupancy, speed_of_ao
from arzsumo.model.params import ModelParameters

#: the diagram parameters stage 1 fits, per family (bounds: the identification's own,
#: :data:`arzsumo.identify.objective.DEFAULT_BOUNDS`)
DIAGRAM_WHICH: dict[str, tuple[str, ...]] = {
    "newell": ("wave_speed_h", "wave_speed_a", "ao_max_h", "ao_max_a"),
    "power": ("ao_max_h", "ao_max_a", "gamma_h", "gamma_a"),
}


@dataclass(frozen=True)
class StationaryStates:
    """Block states (one row per block), SI: class densities (veh/m) and speeds (m/s);
    ``run`` is the index of the run a block came from (for the bootstrap)."""

    rho_h: np.ndarray
    rho_a: np.ndarray
    v_h: np.ndarray
    v_a: np.ndarray
    run: np.ndarray

    @property
    def size(self) -> int:
        """Number of blocks."""
        return int(self.rho_h.size)

    def take(self, idx: np.ndarray) -> StationaryStates:
        """The blocks ``idx``."""
        return StationaryStates(self.rho_h[idx], self.rho_a[idx], self.v_h[idx],
                                self.v_a[idx], self.run[idx])

    @staticmethod
    def concat(parts: Sequence[StationaryStates]) -> StationaryStates:
        """Blocks of several runs, each relabelled with its position in ``parts``."""
        cols = [np.concatenate([getattr(p, f) for p in parts])
                for f in ("rho_h", "rho_a", "v_h", "v_a")]
        run = np.concatenate([np.full(p.size, i) for i, p in enumerate(parts)])
        return StationaryStates(*cols, run)


def block_states(data: ReplayData, cells: int = 2, periods: int = 30,
                 start: float = 0.0) -> StationaryStates:
    """The blocks of ``cells`` cells x ``periods`` periods of ``data`` after ``start`` (s).

    Within a block, density is the mean over its cells and periods and speed is mean flow
    over mean density (Edie). A cell without vehicles of a class has no speed (NaN) and
    carries no flow; a block with an unobserved density, or without a vehicle of either
    class, is dropped.
    """
    require(cells >= 1 and periods >= 1, "block", (cells, periods),
            "at least one cell and one period", IdentifyError)
    f = np.asarray(data.fields)[np.asarray(data.t) > start]
    nt, nx = f.shape[0] // periods, f.shape[2] // cells
    if nt == 0 or nx == 0:
        empty = np.zeros(0)
        return StationaryStates(empty, empty, empty, empty, empty.astype(int))
    f = f[:nt * periods, :, :nx * cells].reshape(nt, periods, 4, nx, cells)
    dens = f[:, :, [0, 2]]
    cell_flow = np.where(dens > 0, dens * f[:, :, [1, 3]], 0.0)
    rho = dens.mean(axis=(1, 4))                                     # (nt, 2, nx)
    flow = cell_flow.mean(axis=(1, 4))
    with np.errstate(invalid="ignore", divide="ignore"):
        speed = flow / rho
    keep = (np.isfinite(rho).all(axis=1) & np.isfinite(speed).all(axis=1)
            & (rho > 0).all(axis=1))
    r, v = rho.transpose(1, 0, 2)[:, keep], speed.transpose(1, 0, 2)[:, keep]
    return StationaryStates(r[0], r[1], v[0], v[1], np.zeros(r.shape[1], int))


@dataclass(frozen=True)
class DiagramFit:
    """Stage 1's result: the fitted parameters and how well they hold (SI).

    ``rmse`` per class is the speed RMSE over the blocks (m/s); ``lambda_4`` is the
    fitted model's at the operating point (m/s) against the target ``wave_speed``.
    """

    params: ModelParameters
    which: tuple[str, ...]
    values: np.ndarray
    sigma: np.ndarray
    bootstrap_sigma: np.ndarray | None
    rmse: dict[str, float]
    lambda_4: float
    wave_speed: float
    blocks: int

    def as_dict(self) -> dict[str, object]:
        """Plain numbers (SI), for the result files."""
        columns = {"": self.values, "_sigma": self.sigma,
                   "_bootstrap_sigma": self.bootstrap_sigma}
        out: dict[str, object] = {f"{n}{suffix}": float(v) for suffix, col in columns.items()
                                  if col is not None
                                  for n, v in zip(self.which, col, strict=True)}
        out.update({"rmse_h": self.rmse["h"], "rmse_a": self.rmse["a"],
                    "lambda_4": self.lambda_4, "wave_speed": self.wave_speed,
                    "blocks": self.blocks, "family": self.params.family})
        return out


def _speed_scale(s: StationaryStates) -> float:
    """The mean observed speed, m/s: the speed residual is relative to it."""
    return float(np.mean(np.concatenate([s.v_h, s.v_a])))


def _speed_residual(p: ModelParameters, s: StationaryStates, scale: float) -> np.ndarray:
    ao = area_occupancy(p, s.rho_h, s.rho_a)
    if np.any(ao >= np.minimum(p.ao_max_h, p.ao_max_a)):
        return np.full(2 * s.size, INADMISSIBLE)
    ve_h, ve_a = speed_of_ao(p, ao)
    return np.concatenate([ve_h - s.v_h, ve_a - s.v_a]) / scale


def _residual(p: ModelParameters, s: StationaryStates, target: WaveTarget,
              scale: float) -> np.ndarray:
    speed = _speed_residual(p, s, scale)
    gap = target.gap(p)
    return np.append(speed, target.weight * math.sqrt(speed.size) * gap / math.sqrt(2.0))


def ao_floor(p: ModelParameters, s: StationaryStates) -> float:
    """The least jam occupancy (or AO_max) that leaves every block admissible."""
    return float(np.max(area_occupancy(p, s.rho_h, s.rho_a))) * (1.0 + 1e-3)


def _lower(name: str, floor: float) -> float:
    low = DEFAULT_BOUNDS[name][0]
    return max(low, floor) if name.startswith("ao_max") else low


def _solve(guess: ModelParameters, which: tuple[str, ...], s: StationaryStates,
           target: WaveTarget, floor: float | None = None
           ) -> tuple[ModelParameters, np.ndarray]:
    """Least squares in z = log(p / p0): the parameters and the Jacobian in z; the jam
    occupancies (AO_max) at least ``floor`` (default: just above every block's AO)."""
    floor = max(ao_floor(guess, s), floor or 0.0)
    require(floor < DEFAULT_BOUNDS["ao_max_h"][1], "largest block AO", round(floor, 4),
            "below 1 (the blocks are not area occupancies otherwise)", IdentifyError)
    guess = replace(guess, **{n: max(getattr(guess, n), floor * (1 + 1e-3))
                              for n in which if n.startswith("ao_max")})
    p0 = np.array([getattr(guess, n) for n in which])
    lo = np.log(np.array([_lower(n, floor) for n in which]) / p0)
    hi = np.log(np.array([DEFAULT_BOUNDS[n][1] for n in which]) / p0)
    scale = _speed_scale(s)

    def at(z: np.ndarray) -> ModelParameters:
        return replace(guess, **{n: float(v) for n, v in zip(which, p0 * np.exp(z),
                                                              strict=True)})

    sol = least_squares(lambda z: _residual(at(z), s, target, scale), np.zeros(len(which)),
                        bounds=(lo, hi), x_scale=1.0, diff_step=1e-6)
    return at(sol.x), sol.jac


def fit_diagram(guess: ModelParameters, states: StationaryStates, wave_speed: float,
                operating_point: tuple[float, float], *, wave_weight: float = 1.0,
                bootstrap: int = 0, seed: int = 0, floor: float | None = None
                ) -> DiagramFit:
    """Fit the diagram of ``guess.family`` to ``states`` and the measured ``wave_speed``.

    Parameters
    ----------
    guess : ModelParameters
        Start; its family chooses the fitted names (:data:`DIAGRAM_WHICH`); the others
        (free-flow speeds, the corner, relaxation times) stay as they are.
    states : StationaryStates
        The stationary blocks (at least 10).
    wave_speed : float
        The measured upstream wave speed c, m/s (< 0).
    operating_point : (rho_h, rho_a)
        Densities (veh/m) where lambda_4 is compared with c.
    wave_weight : float
        1 weighs the relative wave gap like the whole relative speed residual.
    bootstrap : int
        Refits over runs drawn with replacement (0: none).
    floor : float, optional
        Least jam occupancy (AO_max) allowed, e.g. what keeps a replay of the runs' cells
        in the model's domain; never below the blocks' largest AO.
    """
    require(states.size >= 10, "stationary blocks", states.size, "at least 10",
            IdentifyError)
    which = DIAGRAM_WHICH[guess.family]
    target = WaveTarget(wave_speed, *operating_point, wave_weight)
    fitted, jac = _solve(guess, which, states, target, floor)
    values = np.array([getattr(fitted, n) for n in which])
    res = _residual(fitted, states, target, _speed_scale(states))
    s2 = float(np.sum(res ** 2)) / max(res.size - len(which), 1)
    cov_z = s2 * np.linalg.pinv(jac.T @ jac)
    sigma = values * np.sqrt(np.clip(np.diag(cov_z), 0.0, None))
    boot = (_bootstrap(fitted, which, states, target, bootstrap, seed, floor) if bootstrap
            else None)
    speed = _speed_residual(fitted, states, 1.0)
    n = states.size
    rmse = {"h": float(np.sqrt(np.mean(speed[:n] ** 2))),
            "a": float(np.sqrt(np.mean(speed[n:] ** 2)))}
    return DiagramFit(fitted, which, values, sigma, boot, rmse, target.lambda_4(fitted),
                      wave_speed, n)


def _bootstrap(fitted: ModelParameters, which: tuple[str, ...], s: StationaryStates,
               target: WaveTarget, draws: int, seed: int, floor: float | None
               ) -> np.ndarray:
    """Spread (sd) of refits over runs drawn with replacement."""
    rng = np.random.default_rng(seed)
    runs = np.unique(s.run)
    refits = []
    for _ in range(draws):
        pick = rng.choice(runs, size=runs.size, replace=True)
        idx = np.concatenate([np.flatnonzero(s.run == r) for r in pick])
        p, _ = _solve(fitted, which, s.take(idx), target, floor)
        refits.append([getattr(p, n) for n in which])
    return np.std(np.array(refits), axis=0, ddof=1)
