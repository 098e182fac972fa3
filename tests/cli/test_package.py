"""The CLI package: one module per command, the commands in their order, ``python -m
arzsumo``, logging configured in the CLI alone."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from arzsumo.cli import main
from arzsumo.version import __version__

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "arzsumo"
#: the tool's commands of ``arzsumo --help``, in order: a run first
TOOL = ["run", "compare", "evaluate", "sweep", "twin", "reproduce", "model", "kernels",
        "verify", "design-check", "identify", "build-net", "calibrate", "alinea-target",
        "network", "list"]
#: then the commands of the installed research package (entry points ``arzsumo.commands``)
COMMANDS = [*TOOL, "premise", "study"]


def test_the_cli_is_a_package_and_no_flat_module_is_left():
    assert (PACKAGE / "cli" / "__init__.py").is_file()
    assert sorted(p.name for p in PACKAGE.glob("cli*.py")) == []


def test_help_lists_every_command_in_order(capsys):
    assert main(["--help"]) == 0
    text = capsys.readouterr().out
    block = text.split("  COMMAND\n", 1)[1].split("\noptions:")[0]
    listed = re.findall(r"^    (\S+)", block, flags=re.MULTILINE)
    assert listed == COMMANDS


def test_without_the_research_package_the_tool_lists_its_own_commands(capsys, monkeypatch):
    import arzsumo.cli as cli

    monkeypatch.setattr(cli, "plugin_registers", lambda: [])
    assert main(["--help"]) == 0
    text = capsys.readouterr().out
    block = text.split("  COMMAND\n", 1)[1].split("\noptions:")[0]
    assert re.findall(r"^    (\S+)", block, flags=re.MULTILINE) == TOOL
    assert text.rstrip().endswith("arzsumo twin paper/base_etc --controller backstepping --out "
                                  "results/twin-bs")
    assert main(["study", "control"]) == 2           # refused by the parser: unknown command


def test_python_m_arzsumo_runs_the_cli():
    env = {"PYTHONPATH": str(PACKAGE.parent), "PATH": "/usr/bin:/bin"}
    for module in ("arzsumo", "arzsumo.cli"):
        proc = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True,
                              text=True, timeout=120, env=env)
        assert proc.returncode == 0 and proc.stdout == f"arzsumo {__version__}\n", proc.stderr


def test_logging_is_configured_in_the_cli_only():
    where = sorted(p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*.py")
                   if "basicConfig(" in p.read_text(encoding="utf-8"))
    assert where == ["cli/__init__.py"]
