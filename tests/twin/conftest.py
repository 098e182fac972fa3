"""Fixtures of the twin tests."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.model import PRESETS, equilibrium_from_densities


@pytest.fixture(params=["power", "newell"])
def any_family_eq(request):
    """The paper's base equilibrium densities on each fundamental-diagram family."""
    from tests.conftest import NEWELL_CHANGES

    p = PRESETS["paper_base"]
    params = p.params if request.param == "power" else p.params.with_(**NEWELL_CHANGES)
    return equilibrium_from_densities(params, p.rho_h, p.rho_a)


@pytest.fixture
def base_eq():
    p = PRESETS["paper_base"]
    return equilibrium_from_densities(p.params, p.rho_h, p.rho_a)


@pytest.fixture
def star(base_eq):
    """(rho_h*, v_h*, rho_a*, v_a*) as a column, SI."""
    eq = base_eq
    return np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
