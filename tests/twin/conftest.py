"""Fixtures of the twin tests."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.model import PRESETS, equilibrium_from_densities


@pytest.fixture
def base_eq():
    p = PRESETS["paper_base"]
    return equilibrium_from_densities(p.params, p.rho_h, p.rho_a)


@pytest.fixture
def star(base_eq):
    """(rho_h*, v_h*, rho_a*, v_a*) as a column, SI."""
    eq = base_eq
    return np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
