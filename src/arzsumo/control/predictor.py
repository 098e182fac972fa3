"""Delay predictor: the scaled Riemann state theta seconds ahead by linear transport.

A command U-bar issued at t reaches w-(L) = R w+(L) + U-bar (clpsys4) at t + theta; a law
evaluated on the predicted w-bar(t + theta) compensates the dead time (Krstic's
predictor feedback; :mod:`arzsumo.control.compensation`). The prediction follows the
characteristics of clpsys1-clpsys4 over theta: in scaled variables the diagonal of the
source is absorbed, and the in-domain coupling Sigma(x) (zero diagonal) is neglected over
the short horizon (error O(theta ||Sigma||), ||Sigma|| below 0.02 1/s on paper_base and
the default). So

* w+_i(x, t + theta) = w+_i(x - lambda_i theta, t) where the foot lies in [0, L]; else
  the characteristic left x = 0 at t + s, s = theta - x / lambda_i, where
  w+_i(0) = Q_i w-(0, t + s) = Q_i w-(Lambda- s, t) (clpsys3);
* w-(x, t + theta) = w-(x + Lambda- theta, t) where the foot lies in [0, L]; else it left
  x = L at t + s, s = theta - (L - x) / Lambda-, where w-(L) = R w+(L, t + s) + U-bar(t + s)
  (clpsys4), with w+_i(L, t + s) = w+_i(L - lambda_i s, t) and U-bar(t + s) the input
  already committed: with a dead time theta it is the command issued at t + s - theta,
  in the past, so the controller knows it (``u_bar_ahead``).

theta must be shorter than L / max |lambda| (one boundary reflection at most).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from arzsumo.errors import ModelError, require
from arzsumo.model.characteristic import CharacteristicSystem

#: U-bar at offsets s in (0, theta] after now (vectorised), scaled units of clpsys4
UBarAhead = Callable[[np.ndarray], np.ndarray]


def held(u_bar: float) -> UBarAhead:
    """U-bar held at ``u_bar`` over the prediction horizon (no command in the pipeline)."""
    return lambda s: np.full(np.shape(s), float(u_bar))


def committed(times: np.ndarray, u_bar: np.ndarray, now: float, delay: float) -> UBarAhead:
    """U-bar that reaches the boundary after ``now``: commands issued at ``times`` (s,
    ascending, zero-order hold) act ``delay`` s later; 0 before the first command."""
    t_cmd, u = np.asarray(times, float), np.asarray(u_bar, float)

    def ahead(s: np.ndarray) -> np.ndarray:
        if u.size == 0:
            return np.zeros(np.shape(s))
        idx = np.searchsorted(t_cmd, now + np.asarray(s, float) - delay, side="right") - 1
        return np.where(idx >= 0, u[np.clip(idx, 0, None)], 0.0)

    return ahead


def predict_riemann(system: CharacteristicSystem, x: np.ndarray, w_bar: np.ndarray,
                    delay: float, u_bar_ahead: UBarAhead | None = None) -> np.ndarray:
    """Scaled Riemann state ``delay`` s ahead by linear transport along characteristics.

    Parameters
    ----------
    system : CharacteristicSystem
        Speeds lambda (m/s), boundary coefficients Q, R and length L (m).
    x : ndarray, shape (N+1,)
        Ascending nodes from 0 to L, m.
    w_bar : ndarray, shape (n+1, N+1)
        Scaled Riemann variables now (clpsys1).
    delay : float
        Prediction horizon theta, s, in [0, L / max |lambda|).
    u_bar_ahead : callable, optional
        U-bar at offsets s in (0, theta] (scaled units); default 0 (the equilibrium).

    Returns
    -------
    ndarray, shape (n+1, N+1)
        Predicted w-bar(x, t + theta).
    """
    x, w_bar = np.asarray(x, float), np.asarray(w_bar, float)
    n, length = system.n, system.length
    require(w_bar.shape == (n + 1, x.size), "w_bar", w_bar.shape,
            f"shape ({n + 1}, {x.size})", ModelError)
    horizon = length / float(np.abs(system.lam).max())
    require(0.0 <= delay < horizon, "delay", delay, f"a time in [0, {horizon:.4g}) s "
            "(one boundary reflection at most)", ModelError)
    ahead = u_bar_ahead or held(0.0)
    lam_minus = system.lam_minus
    out = np.empty_like(w_bar)
    for i in range(n):
        lam = float(system.lam[i])
        foot = x - lam * delay
        inside = np.interp(np.clip(foot, 0.0, length), x, w_bar[i])
        s = delay - x / lam                            # > 0 where the foot is before 0
        from_inlet = system.Q[i] * np.interp(np.clip(lam_minus * s, 0.0, length), x,
                                             w_bar[n])
        out[i] = np.where(foot >= 0, inside, from_inlet)
    foot = x + lam_minus * delay
    inside = np.interp(np.clip(foot, 0.0, length), x, w_bar[n])
    s = np.clip(delay - (length - x) / lam_minus, 0.0, None)   # > 0: left x = L at t + s
    w_plus_l = np.stack([np.interp(length - system.lam[i] * s, x, w_bar[i]) for i in range(n)])
    from_outlet = system.R @ w_plus_l + ahead(s)
    out[n] = np.where(foot <= length, inside, from_outlet)
    return out
