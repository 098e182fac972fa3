"""The files shipped inside the package, and the repository paths that link to them."""

from pathlib import Path

import pytest

import arzsumo
from arzsumo.resources import (
    default_scenario,
    shipped_nets_dir,
    shipped_scenarios_dir,
    shipped_sweeps_dir,
)
from arzsumo.scenario import load_scenario
from arzsumo.sweep.spec import load_sweep

ROOT = Path(__file__).resolve().parents[1]
NET_FILES = ("ramp.net.xml", "ramp.rou.xml", "ramp.sumocfg", "ramp.nod.xml", "ramp.edg.xml",
             "ramp.con.xml", "ramp.tll.xml")
SWEEPS = ("constant_release_sumo", "demand_sumo", "demand_twin", "penetration_deadband_sumo",
          "penetration_legacy_sumo", "penetration_sumo", "penetration_twin",
          "sensitivity_sumo", "sensitivity_twin")


def test_shipped_dirs_are_inside_the_package_and_hold_their_files():
    pkg = Path(arzsumo.__file__).parent
    assert shipped_nets_dir() == pkg / "data" / "sumo_nets"
    assert shipped_scenarios_dir() == pkg / "data" / "scenarios"
    for name in NET_FILES:
        assert (shipped_nets_dir() / name).is_file(), name
    assert sorted(p.stem for p in shipped_sweeps_dir().glob("*.toml")) == list(SWEEPS)
    assert len(list((shipped_scenarios_dir() / "paper").glob("*.toml"))) == 20
    sc = load_scenario(default_scenario())
    assert sc.name == "default" and sc.sumo.demand_h * 3600 == pytest.approx(3198)
    assert sc.sumo.approach_length == 2500 and sc.sumo.fill_duration == sc.run.warmup == 600


@pytest.mark.skipif(not (ROOT / "pyproject.toml").is_file(), reason="needs a source checkout")
def test_repository_root_paths_are_relative_links_to_the_package_data():
    for name, target in (("scenarios", shipped_scenarios_dir()),
                         ("sumo_nets", shipped_nets_dir())):
        link = ROOT / name
        assert link.is_symlink() and not Path(link.readlink()).is_absolute()
        assert link.resolve() == target.resolve()
    assert (ROOT / "scenarios" / "default.toml").read_bytes() == default_scenario().read_bytes()


@pytest.mark.skipif(not (ROOT / "pyproject.toml").is_file(), reason="needs a source checkout")
@pytest.mark.parametrize("name", SWEEPS)
def test_sweep_bases_resolve_through_the_root_link(name):
    """A sweep's base (``../default.toml``) is relative to the sweep file, also via the link."""
    spec = load_sweep(ROOT / "scenarios" / "sweeps" / f"{name}.toml")
    assert spec.base.is_file()
    assert spec.base.resolve().is_relative_to(shipped_scenarios_dir().resolve())
