"""What an agent observes, the same on the twin and in SUMO: spaces and normalisation.

Three observations (``observation=`` ``"state"``, ``"loops"`` or ``"boundary"``), each 4
rows (rho_h, v_h, rho_a, v_a) over places, ``float32``, every row divided by its
equilibrium value (NaN: 1; clipped below at 0; :func:`denormalise` undoes it).
docs/gym.md, "Spaces".
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from arzsumo.bridge.estimator import fill_speeds
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.scenario import Scenario


def scales(eq: Equilibrium) -> np.ndarray:
    """The divisors of the four rows (4, 1): rho_h*, v_h*, rho_a*, v_a* (SI), a zero
    density replaced by the total density."""
    total = eq.rho_h + eq.rho_a
    rho_h = eq.rho_h if eq.rho_h > 0 else total
    rho_a = eq.rho_a if eq.rho_a > 0 else total
    return np.array([rho_h, eq.v_h, rho_a, eq.v_a], float)[:, None]


def denormalise(obs: np.ndarray, eq: Equilibrium) -> np.ndarray:
    """SI fields (rho veh/m, v m/s) of a normalised observation ``obs`` (4, n)."""
    return np.asarray(obs, float) * scales(eq)


class Observer:
    """Builds one kind of observation (module docstring) for a scenario: its equilibrium
    gives the scales, ``[sumo] cell_length_m`` the cells, ``[sensing]`` the stations."""

    def __init__(self, kind: str, scenario: Scenario) -> None:
        self.kind, self.params = kind, scenario.params
        length = scenario.params.length
        n = round(length / scenario.sumo.cell_length)
        self.x_cells = (np.arange(n) + 0.5) * (length / n)
        self.x_loops = (np.asarray(scenario.sensing.loop_x(length), float)
                        if scenario.sensing.loops else np.empty(0))
        self.scale = scales(scenario.equilibrium)
        places = {"state": self.x_cells.size, "loops": self.x_loops.size}.get(kind, 2)
        self.space = spaces.Box(0.0, np.inf, (4, places), np.float32)

    def __call__(self, state: np.ndarray, loops: np.ndarray | None) -> np.ndarray:
        """The observation of ``state`` (4, cells, SI) and the stations' ``loops`` (4,
        stations, SI; None without loops)."""
        if self.kind == "state":
            z = state
        elif self.kind == "loops":
            z = loops
        else:
            z = state[:, [0, -1]] if loops is None else loops[:, [0, -1]]
        out = np.nan_to_num(np.asarray(z, float) / self.scale, nan=1.0, posinf=1.0,
                            neginf=0.0)
        return np.clip(out, 0.0, None).astype(np.float32)

    def loop_fields(self, density: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """Loop readings (2, stations) of density (veh/m) and speed (m/s, NaN where no
        vehicle passed) per class as rows (rho_h, v_h, rho_a, v_a), speeds filled."""
        v_h, v_a = fill_speeds(self.params, density[0], speed[0], density[1], speed[1])
        return np.vstack([density[0], v_h, density[1], v_a])

    def sample(self, x: np.ndarray, fields: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """A twin's fields (4, n) on cells ``x`` at the observed cells and stations."""
        state = np.vstack([np.interp(self.x_cells, x, row) for row in fields])
        loops = (np.vstack([np.interp(self.x_loops, x, row) for row in fields])
                 if self.x_loops.size else None)
        return state, loops
