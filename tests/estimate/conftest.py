"""Synthetic truth for the estimators: the twin on the default scenario's model.

A congested equilibrium (scenarios/legacy_default.toml, lambda_4 = -17.9 km/h) with an 8 %
stop-and-go perturbation (1.5 periods over the road), a slightly varying inlet demand and
an outlet flow swinging by +-12 % of q* with a 100 s period; MUSCL on 100 cells (10 m),
fields kept every second for 300 s. The perturbation grows to about +-30 %.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from arzsumo.model.characteristic import linearize
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.pde import InitialCondition, SolverOptions, TwinStepper, initial_fields
from arzsumo.pde.state import cell_centres
from arzsumo.scenario import load_scenario
from tests.twin.demands import inlet_from_demands

ROOT = Path(__file__).resolve().parents[2]
HORIZON = 300
FINE = 100


@dataclass(frozen=True)
class Truth:
    eq: Equilibrium
    t: np.ndarray            # (n_t,) s
    x: np.ndarray            # (FINE,) m
    fields: np.ndarray       # (n_t, 4, FINE) primitive

    def coarse(self, cells: int) -> np.ndarray:
        """Fields as means over ``cells`` equal cells, (n_t, 4, cells)."""
        return self.fields.reshape(self.t.size, 4, cells, -1).mean(axis=-1)


def default_eq() -> Equilibrium:
    return load_scenario(ROOT / "scenarios" / "legacy_default.toml").equilibrium


@pytest.fixture(scope="session")
def truth() -> Truth:
    eq = default_eq()
    lin = linearize(eq)
    x = cell_centres(eq.params.length, FINE)
    init = initial_fields(InitialCondition("sinusoid", amplitude=(0.08, -0.08, 0.08, -0.08),
                                           wavenumber=1.5), eq, x)
    times = np.arange(0.0, HORIZON + 11.0, 10.0)
    wave = 2 * np.pi * times / 150.0
    inlet = inlet_from_demands(lin, times, eq.q_h * (0.985 + 0.012 * np.sin(wave)),
                               eq.q_a * (0.985 + 0.012 * np.sin(wave + 1.0)))
    stepper = TwinStepper(eq, init, SolverOptions(cells=FINE, scheme="muscl"), inlet)
    fields = [stepper.primitive()]
    for k in range(1, HORIZON + 1):
        stepper.advance(float(k), 0.12 * eq.q * np.sin(2 * np.pi * k / 100.0))
        fields.append(stepper.primitive())
    return Truth(eq, np.arange(HORIZON + 1.0), x, np.array(fields))
