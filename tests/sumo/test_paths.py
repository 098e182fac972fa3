"""Where the network is read from and where ``arzsumo build-net`` may write."""

from pathlib import Path

import pytest

import arzsumo.sumo.paths as paths
from arzsumo.cli import main
from arzsumo.resources import shipped_nets_dir
from arzsumo.sumo.paths import (
    NETS_ENV,
    SumoError,
    build_nets_dir,
    default_nets_dir,
    refuse_installed_nets,
)


def test_shipped_network_is_the_default_and_the_variable_overrides_it(monkeypatch, tmp_path):
    monkeypatch.delenv(NETS_ENV, raising=False)
    assert default_nets_dir() == shipped_nets_dir()
    monkeypatch.setenv(NETS_ENV, str(tmp_path))
    assert default_nets_dir() == tmp_path
    assert build_nets_dir() == tmp_path
    assert build_nets_dir(tmp_path / "x") == tmp_path / "x"


def test_a_source_checkout_builds_into_its_shipped_directory(monkeypatch):
    monkeypatch.delenv(NETS_ENV, raising=False)
    if any(p in ("site-packages", "dist-packages") for p in shipped_nets_dir().parts):
        pytest.skip("the package is installed, not a source checkout")
    assert build_nets_dir() == shipped_nets_dir()


def test_an_installed_network_dir_is_refused():
    installed = Path("/opt/venv/lib/python3.11/site-packages/arzsumo/data/sumo_nets")
    with pytest.raises(SumoError, match=r"sumo_nets' is inside the installed package; "
                                        r"allowed: `arzsumo build-net --out DIR` or "
                                        r"ARZSUMO_SUMO_NETS=DIR"):
        refuse_installed_nets(installed)


def test_build_net_refuses_an_installed_dir_in_one_line_and_writes_nothing(
        monkeypatch, tmp_path, capsys):
    fake = tmp_path / "site-packages" / "arzsumo" / "data" / "sumo_nets"
    fake.mkdir(parents=True)
    monkeypatch.delenv(NETS_ENV, raising=False)
    monkeypatch.setattr(paths, "shipped_nets_dir", lambda: fake)
    assert main(["build-net"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("arzsumo: error: network directory")
    assert "--out DIR" in err and NETS_ENV in err
    assert list(fake.iterdir()) == []
