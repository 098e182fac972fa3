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


@pytest.fixture
def scenario_files():
    from pathlib import Path

    root = Path(__file__).parent.parent / "scenarios"
    files = sorted(p for p in root.rglob("*.toml") if "sweeps" not in p.relative_to(root).parts)
    assert files, "no scenario files shipped"
    return files
