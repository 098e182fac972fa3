"""One choice drives a run: libsumo, traci to sumo, or traci to sumo-gui (no SUMO started).

``arzsumo run --gui`` without a display, or without sumo-gui, ends in one line with exit
code 2 before anything is written.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from arzsumo.cli import main
from arzsumo.sumo import frontend as fe
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.frontend import Frontend
from arzsumo.sumo.paths import SumoError
from arzsumo.sumo.simulation import SumoSimulation

LEGACY = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
RUN = ["run", str(LEGACY), "--gui", "--warmup", "5", "--horizon", "5", "--quiet"]


def _command(frontend: str, workdir: Path) -> list[str]:
    sim = SumoSimulation(Path("net.xml"), Path("rou.xml"), SumoConfig(), frontend=frontend,
                         output_dir=workdir)
    try:
        return sim.command()
    finally:
        sim.close()


def test_one_choice_sets_the_module_and_the_binary():
    assert [(Frontend(n).module_name, Frontend(n).binary_name) for n in fe.FRONTENDS] == [
        ("libsumo", "sumo"), ("traci", "sumo"), ("traci", "sumo-gui")]
    assert Frontend("gui").load() is Frontend("traci").load()
    with pytest.raises(SumoError, match="frontend = 'tk' is not allowed: libsumo, traci, gui"):
        Frontend("tk")


def test_gui_builds_a_sumo_gui_command_that_plays_and_quits(tmp_path):
    gui, plain = _command("gui", tmp_path), _command("libsumo", tmp_path)
    assert Path(gui[0]).name == "sumo-gui" and Path(plain[0]).name == "sumo"
    assert gui[1:] == [*plain[1:], "--start", "true", "--quit-on-end", "true"]


def test_gui_without_a_display_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    out = tmp_path / "out"
    assert main([*RUN, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("arzsumo: error: --gui needs a display") and "\n" not in err
    assert not out.exists()


def test_gui_without_sumo_gui_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("DISPLAY", ":99")
    monkeypatch.setitem(fe.FRONTENDS, "gui", ("traci", "sumo-gui-not-installed"))
    out = tmp_path / "out"
    assert main([*RUN, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "binary = 'sumo-gui-not-installed' is not in" in err and "\n" not in err
    assert not out.exists()


@pytest.mark.sumo
def test_gui_on_a_display_it_cannot_open_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("DISPLAY", ":99")            # no X server there: sumo-gui exits at once
    out = tmp_path / "out"
    assert main([*RUN, "--controller", "open", "--no-plots", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == ("arzsumo: error: SUMO did not start: Could not connect; allowed: --gui "
                   "with a display sumo-gui can open (DISPLAY = ':99'), or the run without "
                   "--gui")
    assert not out.exists()
