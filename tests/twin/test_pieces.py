"""State conversions, fluxes, relaxation, boundaries, initial conditions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arzsumo.errors import ModelError
from arzsumo.pde import InitialCondition, Inlet, initial_fields, outlet_flux
from arzsumo.pde.flux import (
    FLUXES,
    LIMITERS,
    muscl_faces,
    physical_flux,
    state_speeds,
    waves,
)
from arzsumo.pde.source import relax
from arzsumo.pde.state import (
    cell_centres,
    domain_violation,
    macro_state,
    to_conserved,
    to_primitive,
)

from .demands import inlet_from_demands


def _states(eq, n=7, seed=1):
    rng = np.random.default_rng(seed)
    prim = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None] * (
        1.0 + 0.1 * rng.standard_normal((4, n)))
    return prim, to_conserved(eq.params, *prim)


def test_conversions_round_trip(base_eq):
    prim, q = _states(base_eq)
    np.testing.assert_allclose(to_primitive(base_eq.params, q), prim, rtol=1e-13)
    x = np.linspace(0, 1000, prim.shape[1])
    state = macro_state(base_eq.params, 3.0, x, q)
    assert state.t == 3.0
    back = to_conserved(base_eq.params, state.rho_h, state.v_h, state.rho_a, state.v_a)
    np.testing.assert_allclose(back, q, rtol=1e-13)


def test_y_vanishes_at_equilibrium(base_eq):
    q = to_conserved(base_eq.params, base_eq.rho_h, base_eq.v_h, base_eq.rho_a, base_eq.v_a)
    assert abs(q[1]) < 1e-15 and abs(q[3]) < 1e-15


def test_wave_speeds_at_equilibrium_are_the_linearised_eigenvalues(preset_lin):
    eq = preset_lin.equilibrium
    q = to_conserved(eq.params, [eq.rho_h], [eq.v_h], [eq.rho_a], [eq.v_a])
    v_h, v_a, low, high = (float(a[0]) for a in state_speeds(eq.params, q))
    np.testing.assert_allclose([v_h, high, v_a, low], preset_lin.eigenvalues, rtol=1e-12)


@pytest.mark.parametrize("name", sorted(FLUXES))
def test_numerical_fluxes_are_consistent_and_conservative(base_eq, name):
    _, q = _states(base_eq)
    w = waves(base_eq.params, q)
    flux, smax = FLUXES[name](w, w)
    np.testing.assert_allclose(flux, physical_flux(q, w.v_h, w.v_a), rtol=1e-13)
    assert np.all(smax > 0)


def test_hll_upwinds_each_family(base_eq):
    """All speeds >= 0 (free flow): HLL is the donor cell from the left."""
    p = base_eq.params
    q = to_conserved(p, [0.01, 0.012], [20.0, 19.0], [0.01, 0.011], [15.0, 14.0])
    w = waves(p, q)
    assert np.all(w.lo > 0)
    flux, _ = FLUXES["hll"](w.sel(slice(0, 1)), w.sel(slice(1, 2)))
    np.testing.assert_allclose(flux[:, 0], w.f[:, 0], rtol=1e-14)


@pytest.mark.parametrize("name", sorted(LIMITERS))
def test_limiters_keep_faces_between_neighbours(name):
    rng = np.random.default_rng(3)
    r = rng.random((4, 52))
    east, west = muscl_faces(r, LIMITERS[name])
    lo = np.minimum(np.minimum(r[:, :-2], r[:, 1:-1]), r[:, 2:])
    hi = np.maximum(np.maximum(r[:, :-2], r[:, 1:-1]), r[:, 2:])
    for face in (east, west):
        assert np.all(face >= lo - 1e-15) and np.all(face <= hi + 1e-15)
    line = np.tile(np.arange(10.0), (4, 1))                 # linear data: exact slopes
    east, _ = muscl_faces(line, LIMITERS[name])
    np.testing.assert_allclose(east, line[:, 1:-1] + 0.5)


def test_relaxation_step_is_exact_and_unconditionally_stable(base_eq):
    p = base_eq.params
    _, q = _states(base_eq)
    dt = 7.3
    out = relax(p, q, dt)
    np.testing.assert_array_equal(out[[0, 2]], q[[0, 2]])           # densities untouched
    np.testing.assert_allclose(out[1], q[1] * math.exp(-dt / p.tau_h), rtol=1e-15)
    np.testing.assert_allclose(out[3], q[3] * math.exp(-dt / p.tau_a), rtol=1e-15)
    np.testing.assert_allclose(relax(p, relax(p, q, 2.0), 5.3), out, rtol=1e-14)  # semigroup
    huge = relax(p, q, 1e6)                                          # dt >> tau: y -> 0
    assert np.all(np.abs(huge[[1, 3]]) < 1e-300) and np.all(np.isfinite(huge))


def test_inlet_at_equilibrium_returns_the_equilibrium(base_lin):
    eq = base_lin.equilibrium
    inlet = Inlet.at_equilibrium(base_lin)
    z = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])
    np.testing.assert_allclose(inlet.boundary_primitive(0.0, z), z, rtol=1e-13)
    flux, _ = inlet.boundary_flux(eq.params, 0.0, z)
    assert flux[0] + flux[2] == pytest.approx(eq.q, rel=1e-14)


def test_inlet_keeps_densities_flow_and_outgoing_invariant(base_lin):
    eq = base_lin.equilibrium
    inlet = Inlet.at_equilibrium(base_lin)
    z0 = np.array([eq.rho_h * 1.05, eq.v_h * 0.9, eq.rho_a * 0.97, eq.v_a * 1.1])
    zb = inlet.boundary_primitive(0.0, z0)
    assert zb[0] == eq.rho_h and zb[2] == eq.rho_a
    assert zb[0] * zb[1] + zb[2] * zb[3] == pytest.approx(eq.q, rel=1e-13)
    assert base_lin.T[3] @ zb == pytest.approx(base_lin.T[3] @ z0, rel=1e-12)


def test_inlet_from_demands_interpolates(base_lin):
    eq = base_lin.equilibrium
    inlet = inlet_from_demands(base_lin, np.array([0.0, 100.0]),
                               np.array([eq.q_h, 1.1 * eq.q_h]), np.array([eq.q_a, eq.q_a]))
    assert inlet.flow(0.0) == pytest.approx(eq.q)
    assert inlet.flow(50.0) == pytest.approx(eq.q + 0.05 * eq.q_h)
    assert inlet.rho_h(0.0) == pytest.approx(eq.rho_h, rel=1e-8)


def test_outlet_split_follows_arriving_class_flows(base_eq):
    eq = base_eq
    q = to_conserved(eq.params, eq.rho_h, eq.v_h * 1.1, eq.rho_a, eq.v_a)
    flux, limited = outlet_flux(q, eq.v_h * 1.1, eq.v_a, 2.0)
    assert not limited
    assert flux[0] + flux[2] == pytest.approx(2.0)
    share = eq.rho_h * eq.v_h * 1.1 / (eq.rho_h * eq.v_h * 1.1 + eq.q_a)
    assert flux[0] / 2.0 == pytest.approx(share)
    assert flux[1] == pytest.approx(q[1] / q[0] * flux[0])        # marker leaves with vehicles
    free, limited = outlet_flux(q, eq.v_h, eq.v_a, 50.0, congested=False)
    assert limited and free[0] + free[2] == pytest.approx(eq.q)   # cannot pull more than arrives


def test_initial_profiles(base_eq):
    eq = base_eq
    x = cell_centres(1000.0, 100)
    lin = initial_fields(InitialCondition("linear", amplitude=0.1), eq, x)
    np.testing.assert_allclose(lin[0], eq.rho_h * (1 + 0.1 * x / 1000.0))
    np.testing.assert_allclose(lin[3], eq.v_a * (1 - 0.1 * x / 1000.0))
    non = initial_fields(InitialCondition("nonrecurrent", amplitude=0.1), eq, x)
    assert non[0].argmax() in (49, 50) and non[1].argmin() in (49, 50)
    sine = initial_fields(InitialCondition(amplitude=(0.05, -0.02, 0.0, 0.0),
                                           wavenumber=(1, 3, 1, 1)), eq, x)
    assert sine[0].max() == pytest.approx(eq.rho_h * 1.05, rel=1e-3)
    np.testing.assert_allclose(sine[2], eq.rho_a)
    with pytest.raises(ModelError, match="kind = 'bumpy' is not allowed"):
        InitialCondition(kind="bumpy")
    with pytest.raises(ModelError, match="fields = 3 is not allowed: 4 arrays"):
        InitialCondition("array", fields=(x, x, x))
    with pytest.raises(ModelError, match=r"fields = \(4, 50\) is not allowed: 4 arrays of 100"):
        initial_fields(InitialCondition("array", fields=(x[:50],) * 4), eq, x)


def test_random_wave_is_seeded_smooth_and_keeps_stop_and_go_signs(base_eq):
    eq = base_eq
    x = cell_centres(1000.0, 200)
    amp = (0.02, -0.03, 0.02, -0.03)
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]

    def rel(seed: int) -> np.ndarray:
        ic = InitialCondition("random", amplitude=amp, wavenumber=3, seed=seed)
        return initial_fields(ic, eq, x) / star - 1.0

    a, b, c = rel(1), rel(1), rel(2)
    np.testing.assert_array_equal(a, b)                         # same seed, same wave
    assert np.max(np.abs(a[0] - c[0])) > 1e-3                   # another seed, another wave
    np.testing.assert_allclose(np.max(np.abs(a), axis=1), np.abs(amp), rtol=1e-12)
    np.testing.assert_allclose(a[1], -1.5 * a[0], atol=1e-15)   # dense where slow
    # at most 3 periods over the road: the shape lies in the span of modes 1..3 to 1e-12
    s = x / 1000.0
    basis = np.concatenate([np.sin(2 * np.pi * m * s)[None] for m in (1, 2, 3)]
                           + [np.cos(2 * np.pi * m * s)[None] for m in (1, 2, 3)])
    coef, *_ = np.linalg.lstsq(basis.T, a[0], rcond=None)
    assert np.max(np.abs(basis.T @ coef - a[0])) < 1e-12
    with pytest.raises(ModelError, match=r"wavenumber = 2\.5 is not allowed: an integer"):
        InitialCondition("random", wavenumber=2.5)


def test_domain_violation_names_variable_position(base_eq):
    p = base_eq.params
    x = cell_centres(1000.0, 4)
    prim = np.array([[0.11] * 4, [10.0] * 4, [0.095] * 4, [5.0] * 4])
    q = to_conserved(p, *prim)
    assert domain_violation(p, q, x) is None
    bad = q.copy()
    bad[2, 2] = -0.001
    assert domain_violation(p, bad, x) == ("rho_a = -0.001 at x = 625.0 m (cell 2): "
                                           "density not positive")
    bad = q.copy()
    bad[1, 3] = np.nan
    assert domain_violation(p, bad, x).startswith("y_h = nan at x = 875.0 m (cell 3)")
