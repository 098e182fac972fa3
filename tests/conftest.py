"""Shared fixtures (``scenario_files``: the scenario files; sweep files are elsewhere)."""

from __future__ import annotations

import pytest

from arzsumo.model import PRESETS, equilibrium_from_densities, linearize


@pytest.fixture(params=sorted(PRESETS))
def preset_lin(request):
    """The linearisation of each paper preset."""
    p = PRESETS[request.param]
    return linearize(equilibrium_from_densities(p.params, p.rho_h, p.rho_a))


@pytest.fixture
def base_lin():
    p = PRESETS["paper_base"]
    return linearize(equilibrium_from_densities(p.params, p.rho_h, p.rho_a))


#: a smoothed-Newell model at the paper's base densities (AO 0.709): jam occupancies 0.95
#: (HV) and 0.9 (AV), waves at 35 km/h, corner order 4; speeds 11.9 and 9.4 km/h. (With
#: equal class parameters both speeds coincide and the kernels need many more cells.)
NEWELL_CHANGES = {"family": "newell", "ao_max_h": 0.95, "ao_max_a": 0.9,
                  "wave_speed_h": 35 / 3.6, "wave_speed_a": 35 / 3.6, "corner": 4.0}


@pytest.fixture
def newell_eq():
    """The paper's base equilibrium densities on the smoothed-Newell family."""
    p = PRESETS["paper_base"]
    return equilibrium_from_densities(p.params.with_(**NEWELL_CHANGES), p.rho_h, p.rho_a)


@pytest.fixture
def newell_lin(newell_eq):
    return linearize(newell_eq)


@pytest.fixture
def scenario_files():
    from pathlib import Path

    root = Path(__file__).parent.parent / "scenarios"
    files = sorted(p for p in root.rglob("*.toml") if "sweeps" not in p.relative_to(root).parts)
    assert files, "no scenario files shipped"
    return files
