"""Macro to micro: initial vehicles on ``main`` from density and speed profiles per class
(docs/sumo.md, "Macro to micro").

Each class's cumulative count N_i(x) = integral of rho_i (profiles piecewise constant on
the cells) is inverted at N_i = k + 1/2, which puts the k-th vehicle's front at the
middle of its share of the road. The seed only decides ties between columns. The
vehicles go into the route file, as libsumo's ``vehicle.add`` takes no lateral position.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.errors import ModelError, require
from arzsumo.model.params import ModelParameters
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import InitialVehicle, insertion_columns
from arzsumo.sumo.vtypes import AV_TYPE, HV_TYPE, VehicleType, vehicle_types

#: Number of lateral columns for initial vehicles (d = 2 m on a 6.5 m lane).
COLUMNS = 3


@dataclass(frozen=True)
class PlacementReport:
    """What the placement did: vehicles per class, moved (count, largest shift m), dropped."""

    n_h: int
    n_a: int
    moved: int
    max_shift: float
    dropped: int

    def summary(self) -> str:
        return (f"placed {self.n_h} HV and {self.n_a} AV; moved {self.moved} upstream "
                f"(largest shift {self.max_shift:.2f} m); dropped {self.dropped}")


def _targets(x: np.ndarray, rho: np.ndarray, length: float) -> np.ndarray:
    """Front positions (m) of the vehicles of one class, downstream first."""
    edges = np.concatenate([[0.0], 0.5 * (x[1:] + x[:-1]), [length]])
    cum = np.concatenate([[0.0], np.cumsum(rho * np.diff(edges))])
    n = int(np.floor(cum[-1] + 0.5))
    return np.interp(np.arange(n) + 0.5, cum, edges)[::-1]


def _check_profiles(params: ModelParameters, x: np.ndarray, arrays: list[np.ndarray]) -> None:
    """Each profile has the shape of ``x``, finite values >= 0; ``x`` increases inside (0, L)."""
    for name, a in zip(("rho_h", "v_h", "rho_a", "v_a"), arrays, strict=True):
        require(a.shape == x.shape, name, a.shape, f"the shape of x {x.shape}")
        require(bool(np.all(np.isfinite(a)) and np.all(a >= 0)), name, "array",
                "finite values >= 0")
    require(x.ndim == 1 and x.size >= 1 and bool(np.all(np.diff(x) > 0))
            and x[0] > 0 and x[-1] < params.length, "x", "array",
            f"increasing cell centres inside (0, {params.length}) m")


def _candidates(x: np.ndarray, rho_h: np.ndarray, rho_a: np.ndarray,
                length: float) -> list[tuple[float, str, int]]:
    """(target front m, class, index in its class) of every vehicle, downstream first."""
    cand = [(p, HV_TYPE, k) for k, p in enumerate(_targets(x, rho_h, length))]
    cand += [(p, AV_TYPE, k) for k, p in enumerate(_targets(x, rho_a, length))]
    cand.sort(key=lambda c: -c[0])
    return cand


def _column(allowed: np.ndarray, target: float, order: np.ndarray) -> int:
    """Best fit: the column with the least room left above ``target`` (m), else the
    roomiest; ``order`` (a random permutation) decides ties."""
    fits = order[allowed[order] >= target]
    return int(fits[np.argmin(allowed[fits])] if fits.size else
               order[np.argmax(allowed[order])])


def _fill_columns(cand: list[tuple[float, str, int]], kinds: dict[str, VehicleType],
                  lats: np.ndarray, length: float, rng: np.random.Generator,
                  ) -> tuple[list[tuple[str, str, float, float]], int, float, int]:
    """Put the candidates, downstream first, into the lateral columns ``lats`` (m): (id,
    class, front m, lateral offset m) of each placed vehicle, the number moved upstream,
    the largest shift (m) and the number dropped."""
    # back of the last vehicle placed in each column (+inf: free)
    back = np.full(lats.size, np.inf)
    placed: list[tuple[str, str, float, float]] = []
    moved, max_shift, dropped = 0, 0.0, 0
    for target, vtype, k in cand:
        t = kinds[vtype]
        allowed = np.minimum(back - t.min_gap, length)
        col = _column(allowed, target, rng.permutation(lats.size))
        front = min(target, float(allowed[col]))
        if front < 0.0:
            dropped += 1
            continue
        if front < target - 1e-9:
            moved += 1
            max_shift = max(max_shift, target - front)
        back[col] = front - t.length
        placed.append((f"{vtype}_init.{k}", vtype, front, float(lats[col])))
    return placed, moved, max_shift, dropped


def place_vehicles(params: ModelParameters, cfg: SumoConfig, x: ArrayLike, rho_h: ArrayLike,
                   v_h: ArrayLike, rho_a: ArrayLike, v_a: ArrayLike,
                   ) -> tuple[list[InitialVehicle], PlacementReport]:
    """Initial vehicles reproducing density profiles on [0, L], and what the placement did.

    The profiles are the class densities ``rho_h``, ``rho_a`` (veh/m) and speeds ``v_h``,
    ``v_a`` (m/s) on the cell centres ``x`` (m, increasing in (0, L)); ``params`` gives the
    road and the spacings, ``cfg`` the seed and the vehicle types. The vehicles are sorted
    by id (HVs ``hv_init.k``, AVs ``av_init.k``).
    """
    x = np.asarray(x, float)
    arrays = [np.asarray(a, float) for a in (rho_h, v_h, rho_a, v_a)]
    _check_profiles(params, x, arrays)
    hv_t, av_t = vehicle_types(params, cfg)
    speeds = {HV_TYPE: arrays[1], AV_TYPE: arrays[3]}
    placed, moved, max_shift, dropped = _fill_columns(
        _candidates(x, arrays[0], arrays[2], params.length), {HV_TYPE: hv_t, AV_TYPE: av_t},
        np.array(insertion_columns(params.road_width, params.vehicle_width, COLUMNS)),
        params.length, np.random.default_rng(cfg.seed))
    out = [InitialVehicle(vid, vtype, front, float(np.interp(front, x, speeds[vtype])), lat)
           for vid, vtype, front, lat in placed]
    out.sort(key=lambda v: v.id)
    n_h = sum(1 for v in out if v.type == HV_TYPE)
    report = PlacementReport(n_h, len(out) - n_h, moved, max_shift, dropped)
    if dropped:
        raise ModelError(f"initial densities do not fit on the road: {report.summary()}; "
                         "allowed: profiles whose area occupancy the lane can hold")
    return out, report
