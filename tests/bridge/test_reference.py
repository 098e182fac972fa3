"""The warm-up reference (``[estimation] reference = "warmup"``): a PDE law measures its
deviations from the mean state SUMO held in the warm-up."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.reference import reference_shift
from arzsumo.control.base import MacroState
from arzsumo.control.etc import PAPER_DESIGN
from arzsumo.control.registry import ControllerInputs, controller_spec
from arzsumo.kernel_cache import cached_kernels
from arzsumo.model.characteristic import linearize
from arzsumo.outputs.bridge import summary
from arzsumo.scenario import load_scenario
from tests.runs import prepared

ROOT = Path(__file__).resolve().parents[2]
LEGACY = ROOT / "scenarios" / "legacy_default.toml"


def _law(lin, cells: int):
    ctrl = controller_spec("backstepping", "sumo").build(
        ControllerInputs(lin, cached_kernels(lin.system, cells), PAPER_DESIGN))
    ctrl.reset()
    return ctrl


def _state(x, f, t=0.0):
    return MacroState(t, x, f[0], f[1], f[2], f[3])


def test_the_warmup_mean_state_gets_no_control(tmp_path, monkeypatch):
    """A warm-up holding a constant off-equilibrium field: the law answers it with a large
    U; measured from the warm-up mean, with 0; a state off that mean gets the law's answer
    to the difference (the law is linear)."""
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    sc = load_scenario(LEGACY)
    eq, lin = sc.equilibrium, linearize(sc.equilibrium)
    x = (np.arange(20) + 0.5) * 50.0
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None] * np.ones((4, 20))
    held = star * np.array([1.05, 0.85, 1.02, 0.7])[:, None]
    rng = np.random.default_rng(1)
    warm = [held + rng.normal(0, 1e-3, held.shape) * star for _ in range(400)]
    law = _law(lin, 40)
    assert abs(law.check(_state(x, held))) > 0.05                 # > 180 veh/h
    shift = reference_shift("warmup", warm, eq, window=300.0, period=1.0)
    mean = np.mean(warm[-300:], axis=0)
    np.testing.assert_allclose(shift.offset, mean - star, rtol=0, atol=1e-15)
    assert abs(_law(lin, 40).check(shift.apply(_state(x, mean)))) < 1e-9
    moved = mean + 0.03 * star * np.sin(np.pi * x / 1000.0)
    expected = _law(lin, 40).check(_state(x, star + (moved - mean)))
    assert _law(lin, 40).check(shift.apply(_state(x, moved))) == pytest.approx(
        expected, abs=1e-12)
    none = reference_shift("equilibrium", warm, eq, 300.0, 1.0)
    assert not none.offset.any()
    with pytest.raises(ValueError, match="reference 'mean'"):
        reference_shift("mean", warm, eq, 300.0, 1.0)


@pytest.mark.sumo
def test_in_sumo_the_first_command_differs_by_the_law_of_the_offset(tmp_path, monkeypatch):
    """Same seed, same warm-up: the first check of backstepping measured from the warm-up
    differs from the one measured from the equilibrium by exactly the law's answer to the
    offset; the summary reports the offset."""
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    sc = load_scenario(LEGACY)

    def run(reference: str):
        changes = {"estimation.reference": reference, "estimation.reference_window_s": 30,
                   "run.kernel_cells": 40, "run.twin_cells": 40}
        return run_cosimulation(prepared(sc, changes, controller="backstepping",
                                         warmup=60.0, horizon=10.0, seed=7))

    plain, shifted = run("equilibrium"), run("warmup")
    assert plain.shift is None and shifted.shift is not None
    off = shifted.shift.offset
    lin = linearize(sc.equilibrium)
    eq = sc.equilibrium
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
    u_offset = _law(lin, 40).check(_state(plain.x, star + off))
    assert abs(u_offset) > 1e-3                   # the warm-up is off the equilibrium
    u0_plain, u0_shifted = plain.periods["u_raw"][0], shifted.periods["u_raw"][0]
    assert u0_shifted == pytest.approx(u0_plain - u_offset, abs=1e-9)
    est = summary(shifted)["estimation"]
    assert est["reference"] == "warmup"
    assert est["reference_offset"]["v_h"] == pytest.approx(off[1].mean(), abs=1e-12)
    assert summary(plain)["estimation"]["reference_offset"] is None
