import numpy as np
import pytest

from arzsumo import kernel_cache
from arzsumo.kernel_cache import cached_kernels, kernel_key
from arzsumo.model import PRESETS, equilibrium_from_densities, linearize


@pytest.fixture(scope="module")
def system():
    p = PRESETS["paper_base"]
    return linearize(equilibrium_from_densities(p.params, p.rho_h, p.rho_a)).system


def _entry(tmp_path, system, n):
    return tmp_path / "kernels" / f"{kernel_key(system, n)}.npz"


def test_second_call_skips_the_solve(tmp_path, system, monkeypatch):
    first = cached_kernels(system, 20, tmp_path)
    assert _entry(tmp_path, system, 20).exists()

    def boom(*args):
        raise AssertionError("solved again")

    monkeypatch.setattr(kernel_cache, "solve_kernels", boom)
    again = cached_kernels(system, 20, tmp_path)
    np.testing.assert_array_equal(first.K, again.K)


@pytest.mark.parametrize("damage", ["truncate", "garbage", "tamper"])
def test_corrupt_entries_are_recomputed(tmp_path, system, damage):
    good = cached_kernels(system, 20, tmp_path)
    entry = _entry(tmp_path, system, 20)
    if damage == "truncate":
        entry.write_bytes(entry.read_bytes()[:200])
    elif damage == "garbage":
        entry.write_bytes(b"not a zip file at all")
    else:   # valid file, wrong content: checksum must catch it
        with np.load(entry) as d:
            arrays = {k: d[k] for k in d.files}
        arrays["K"] = arrays["K"] * 2
        with open(entry, "wb") as fh:
            np.savez(fh, **arrays)
    again = cached_kernels(system, 20, tmp_path)
    np.testing.assert_array_equal(good.K, again.K)


def test_key_depends_on_system_and_grid(system):
    assert kernel_key(system, 20) != kernel_key(system, 21)
    other = type(system)(system.lam, system.j_hat, system.Q * 1.0001, system.R, system.length)
    assert kernel_key(system, 20) != kernel_key(other, 20)
