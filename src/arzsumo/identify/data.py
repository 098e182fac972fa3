"""One observed run for identification: fields, initial state and boundary data (SI).

:class:`ReplayData` is what the replay twin needs to reproduce a run, and what it is
compared with. It is built from arrays (the SUMO layer aggregates its cells into them)
or from a twin run (:func:`arzsumo.identify.synthetic.synthetic_data`, synthetic data with
known parameters).

Periods: ``t`` holds the ends of the periods, t_0 < t_1 < ... (s, t_0 > 0); period k is
(t_{k-1}, t_k] with t_{-1} = 0. During period k the inlet ghost cell holds
``inlet[k]`` and the outlet carries ``outflow[k]``; ``fields[k]`` is observed at t_k.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.errors import ArzsumoError
from arzsumo.model.params import VARIABLES


class IdentifyError(ArzsumoError, ValueError):
    """Invalid identification input: data shapes or values, parameter names, bounds."""


def _array(name: str, value: ArrayLike, shape: tuple[int, ...], nan_ok: bool = False
           ) -> np.ndarray:
    """A read-only float copy of ``value`` with ``shape``; finite unless ``nan_ok``."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise IdentifyError(f"{name} is not allowed: numbers expected") from None
    if arr.shape != shape:
        raise IdentifyError(f"{name} has shape {arr.shape}; expected {shape}")
    bad = np.isinf(arr) if nan_ok else ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise IdentifyError(f"{name}{list(idx)} = {arr[idx]} is not allowed: a finite number")
    arr.setflags(write=False)
    return arr


def _positive_densities(name: str, arr: np.ndarray, axis: int, strict: bool = True) -> None:
    """Densities (rows 0 and 2 along ``axis``) must be > 0 where given (>= 0 unless
    ``strict``: an observed empty cell has density 0)."""
    rho = np.take(arr, [0, 2], axis=axis)
    bad = rho <= 0.0 if strict else rho < 0.0   # NaN compares False: unobserved is fine
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        allowed = ("densities > 0 (the twin divides by them)" if strict else
                   "densities >= 0")
        raise IdentifyError(f"{name} has density {rho[idx]} veh/m at index {list(idx)}; "
                            f"allowed: {allowed}")


@dataclass(frozen=True)
class ReplayData:
    """One observed run, validated on construction. All SI."""

    #: ends of the periods (T,), s, strictly increasing, t[0] > 0
    t: np.ndarray
    #: observation positions (cell centres) (N,), m, strictly increasing, >= 0
    x: np.ndarray
    #: observed (rho_h veh/m, v_h m/s, rho_a veh/m, v_a m/s) at (t[k], x), (T, 4, N); NaN
    #: where unobserved (e.g. the speed of an empty cell); densities >= 0
    fields: np.ndarray
    #: state at t = 0 on ``x`` (4, N), complete (no NaN), densities > 0
    initial: np.ndarray
    #: boundary state (rho_h, v_h, rho_a, v_a) the inlet ghost cell holds during period k,
    #: (T, 4)
    inlet: np.ndarray
    #: total outflow at x = L during period k (T,), veh/s, >= 0
    outflow: np.ndarray
    #: reference scale per variable (4,) for relative errors (e.g. the equilibrium
    #: values); default: the mean of the observed values per variable
    scale: np.ndarray | None = None
    #: a label for reports (e.g. "seed 3")
    name: str = "run"
    mask: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        t = _array(f"{self.name}: t", self.t, (np.size(self.t),))
        x = _array(f"{self.name}: x", self.x, (np.size(self.x),))
        if t.size < 1 or x.size < 2:
            raise IdentifyError(f"{self.name}: t has {t.size} and x {x.size} values; expected "
                                "at least 1 period and 2 positions")
        if t[0] <= 0.0 or np.any(np.diff(t) <= 0.0):
            raise IdentifyError(f"{self.name}: t = {t[:4].tolist()}... s is not allowed: "
                                "strictly increasing period ends after 0 s")
        if x[0] < 0.0 or np.any(np.diff(x) <= 0.0):
            raise IdentifyError(f"{self.name}: x = {x[:4].tolist()}... m is not allowed: "
                                "strictly increasing positions >= 0 m")
        n_t, n_x = t.size, x.size
        fields_ = _array(f"{self.name}: fields", self.fields, (n_t, 4, n_x), nan_ok=True)
        initial = _array(f"{self.name}: initial", self.initial, (4, n_x))
        inlet = _array(f"{self.name}: inlet", self.inlet, (n_t, 4))
        outflow = _array(f"{self.name}: outflow", self.outflow, (n_t,))
        for label, arr, axis in (("fields", fields_, 1), ("initial", initial, 0),
                                 ("inlet", inlet, 1)):
            _positive_densities(f"{self.name}: {label}", arr, axis, strict=label != "fields")
        if outflow.min() < 0.0:
            raise IdentifyError(f"{self.name}: outflow = {outflow.min()} veh/s is not "
                                "allowed: a flow >= 0 veh/s")
        mask = np.isfinite(fields_)
        mask.setflags(write=False)
        for k, var in enumerate(VARIABLES):
            if not mask[:, k].any():
                raise IdentifyError(f"{self.name}: fields of {var} are all NaN; expected "
                                    "some observed values")
        scale = self.scale
        if scale is None:
            scale = np.array([np.mean(np.abs(fields_[:, k][mask[:, k]])) for k in range(4)])
        scale = _array(f"{self.name}: scale", scale, (4,))
        if scale.min() <= 0.0:
            raise IdentifyError(f"{self.name}: scale = {scale.tolist()} is not allowed: "
                                "4 reference values > 0 (rho_h, v_h, rho_a, v_a)")
        for key, value in (("t", t), ("x", x), ("fields", fields_), ("initial", initial),
                           ("inlet", inlet), ("outflow", outflow), ("scale", scale),
                           ("mask", mask)):
            object.__setattr__(self, key, value)

    @property
    def periods(self) -> int:
        """Number of periods T."""
        return int(self.t.size)

    @classmethod
    def from_arrays(cls, t: ArrayLike, x: ArrayLike, fields: ArrayLike, initial: ArrayLike,
                    inlet: ArrayLike, outflow: ArrayLike, *, scale: ArrayLike | None = None,
                    name: str = "run") -> ReplayData:
        """The data from array-likes (copied, validated); see the class for shapes."""
        return cls(t, x, fields, initial, inlet, outflow, scale, name)  # type: ignore[arg-type]
