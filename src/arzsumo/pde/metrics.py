"""Performance indices of section 5, "Traffic performance evaluation", and run diagnostics.

J_fuel, J_discom, J_TTT, TMT and the total delay, with their formulas and units:
docs/outputs.md, "The performance indices and their units". Each class i in {h, a} is
evaluated with its own density and speed and the total is their sum; a_i = (v_i)_t +
v_i (v_i)_x by central differences (``numpy.gradient``); integrals are cell sums times dx
in space and the trapezoidal rule in time, on the stored fields.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.params import ModelParameters

#: Fuel model coefficients of the paper (b0 1/s, b1 1/m, b2 s^2/m^2, b3 s^2/m^3 as printed).
B_FUEL = (25e-3, 24.5e-6, 125e-6, 32.5e-9)

CLASSES = ("h", "a")


@dataclass(frozen=True)
class ClassIndices:
    """Indices of one class (or their sum): see the module docstring for units."""

    J_fuel: float
    J_discom: float
    J_TTT: float
    TMT: float
    total_delay: float


@dataclass(frozen=True)
class Performance:
    """Performance indices per class and in total."""

    h: ClassIndices
    a: ClassIndices
    total: ClassIndices

    def as_dict(self) -> dict[str, dict[str, float]]:
        """{"h": {...}, "a": {...}, "total": {...}}."""
        return {"h": asdict(self.h), "a": asdict(self.a), "total": asdict(self.total)}


def _integrate(density: np.ndarray, t: np.ndarray, dx: float) -> float:
    """int int density dx dt for density shaped (n_t, n_x)."""
    per_time = density.sum(axis=1) * dx
    return float(np.sum(0.5 * (per_time[1:] + per_time[:-1]) * np.diff(t)))


def acceleration(t: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """a = v_t + v v_x (m/s^2) for v shaped (n_t, n_x), central differences."""
    return np.gradient(v, t, axis=0) + v * np.gradient(v, x, axis=1)


def performance(params: ModelParameters, t: np.ndarray, x: np.ndarray,
                fields: np.ndarray) -> Performance:
    """Indices of fields (n_t, 4, n_x) = (rho_h, v_h, rho_a, v_a) at times ``t``, centres ``x``.

    Parameters
    ----------
    params : ModelParameters
        Supplies the free-flow speeds V_h, V_a (m/s) for the delay.
    t : ndarray (n_t,)
        Output times, s; with fewer than two every index is NaN.
    x : ndarray (n_x,)
        Uniform cell centres, m.
    fields : ndarray (n_t, 4, n_x)
        Densities in veh/m and speeds in m/s.
    """
    b0, b1, b2, b3 = B_FUEL
    dx = float(x[1] - x[0])
    if t.size < 2:                        # a run stopped at once: nothing to integrate
        nan = ClassIndices(*(float("nan"),) * 5)
        return Performance(nan, nan, nan)
    per_class = {}
    for k, (cls, v_free) in enumerate(zip(CLASSES, (params.v_free_h, params.v_free_a),
                                          strict=True)):
        rho, v = fields[:, 2 * k], fields[:, 2 * k + 1]
        a = acceleration(t, x, v)
        a_t = np.gradient(a, t, axis=0)
        fuel = np.maximum(0.0, b0 + b1 * v + b2 * v * a + b3 * v ** 3) * rho
        ttt = _integrate(rho, t, dx)
        tmt = _integrate(rho * v, t, dx)
        per_class[cls] = ClassIndices(_integrate(fuel, t, dx),
                                      _integrate((a ** 2 + a_t ** 2) * rho, t, dx),
                                      ttt, tmt, ttt - tmt / v_free)
    total = ClassIndices(*(getattr(per_class["h"], f) + getattr(per_class["a"], f)
                           for f in ClassIndices.__dataclass_fields__))
    return Performance(per_class["h"], per_class["a"], total)


def relative_change(run: Performance, baseline: Performance) -> dict[str, dict[str, float]]:
    """Change of every index against ``baseline`` (the open loop), in percent.

    As in the paper's tables diffperformance and totaldelay: 100 (run - base) / |base|.
    """
    out: dict[str, dict[str, float]] = {}
    for part, values in run.as_dict().items():
        base = baseline.as_dict()[part]
        out[part] = {k: (100.0 * (v - base[k]) / abs(base[k]) if base[k] else float("nan"))
                     for k, v in values.items()}
    return out


def deviation_norm(eq: Equilibrium, x: np.ndarray, fields: np.ndarray) -> np.ndarray:
    """Relative L2 deviation from ``eq`` at each output time (dimensionless).

    ||z(t)|| = sqrt( (1/L) int_0^L sum_k (z_k(x, t) / z_k*)^2 dx ) over the four variables
    z = (rho_h, v_h, rho_a, v_a): each variable is scaled by its equilibrium value so
    densities and speeds weigh alike.
    """
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[None, :, None]
    rel = (fields - star) / star
    return np.sqrt(np.mean(np.sum(rel ** 2, axis=1), axis=-1))


def events(control_t: np.ndarray, control_u: np.ndarray,
           triggered: list[bool] | None) -> np.ndarray:
    """Boolean mask of the checks at which the applied control was updated.

    Uses the controller's own log (``triggered``) when it has one entry per check, else
    detects changes of the applied U (the first check counts when U differs from 0).
    """
    if triggered is not None and len(triggered) == control_t.size:
        return np.asarray(triggered, bool)
    previous = np.concatenate([[0.0], control_u[:-1]])
    return control_u != previous
