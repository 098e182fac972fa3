"""Command-line nonsense refused in one line (exit 2), help texts, ``arzsumo list``."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import pytest

from arzsumo.argtypes import cells_int, positive_float, positive_int, seed_int
from arzsumo.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("helper", "text", "value"), [
    (positive_float, "0.5", 0.5), (positive_int, "3", 3), (seed_int, "0", 0),
    (seed_int, "2147483647", 2**31 - 1), (cells_int, "4", 4)])
def test_type_helpers_accept(helper, text, value):
    assert helper(text) == value


@pytest.mark.parametrize(("helper", "text", "allowed"), [
    (positive_float, "-5", "a finite number > 0"), (positive_float, "0", "a finite number > 0"),
    (positive_float, "nan", "a finite number > 0"), (positive_float, "inf", "> 0"),
    (positive_float, "ten", "a number"), (positive_int, "0", "an integer >= 1"),
    (positive_int, "1.5", "an integer"), (seed_int, "-1", r"an integer in [0, 2^31)"),
    (seed_int, "2147483648", r"[0, 2^31)"), (cells_int, "3", "an integer >= 4")])
def test_type_helpers_refuse_with_value_and_allowed(helper, text, allowed):
    with pytest.raises(argparse.ArgumentTypeError) as info:
        helper(text)
    assert str(info.value) == f"{text} is not allowed: {allowed}" or allowed in str(info.value)
    assert str(info.value).startswith(f"{text} is not allowed: ")


def run_cli(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arzsumo.cli", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd)


@pytest.mark.parametrize(("args", "message"), [
    (["verify", "--horizon", "-5"], "--horizon = -5 is not allowed: a finite number > 0"),
    (["verify", "--horizon", "0"], "--horizon = 0 is not allowed: a finite number > 0"),
    (["verify", "--period", "0"], "--period = 0 is not allowed"),
    (["kernels", "--cells", "0"], "--cells = 0 is not allowed: an integer >= 4"),
    (["design-check", "--mu", "-1"], "--mu = -1 is not allowed"),
    (["reproduce", "--workers", "0"], "--workers = 0 is not allowed: an integer >= 1"),
    (["reproduce", "--workers", "-2"], "--workers = -2 is not allowed: an integer >= 1"),
    (["sweep", "x.toml", "--workers", "0"], "--workers = 0 is not allowed: an integer >= 1"),
    (["run", "--seed", "-1"], r"--seed = -1 is not allowed: an integer in [0, 2^31)"),
    (["run", "--horizon", "0"], "--horizon = 0 is not allowed: a finite number > 0"),
    (["run", "--horizon", "0.05"], "--horizon = 0.05 is not allowed: a control horizon of at "
                                   "least one control period ([sumo] control_period_s = 1 s)"),
    (["run", "--horizon", "0.05", "--dry-run"], "--horizon = 0.05 is not allowed"),
    (["calibrate", "--seed", "-3"], "--seed = -3 is not allowed"),
    (["calibrate", "--jobs", "0"], "--jobs = 0 is not allowed: an integer >= 1"),
    (["run", "--controller", "pid"], "argument --controller: invalid choice: 'pid'"),
    (["verify", "--bogus"], "unrecognized arguments: --bogus"),
    ([], "the following arguments are required: COMMAND"),
])
def test_nonsense_is_one_line_exit_2(args, message, tmp_path):
    proc = run_cli(*args)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("arzsumo: error: ") and message in proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and "Traceback" not in proc.stderr
    assert proc.stdout == ""


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {c.dest: c.help for c in action._choices_actions}
    assert all(helps.values()) and set(helps) == set(action.choices)
    return action.choices


def test_every_command_has_help_and_description():
    commands = _subparsers(build_parser())
    assert {"model", "kernels", "verify", "design-check", "twin", "reproduce", "build-net",
            "calibrate", "run", "compare", "alinea-target", "sweep", "evaluate", "premise",
            "identify", "list", "study", "network"} == set(commands)
    for name, p in commands.items():
        assert p.description and len(p.description) > 30, name


def test_help_shows_defaults_environment_and_exit_codes(capsys):
    assert main(["--help"]) == 0
    top = capsys.readouterr().out
    for text in ("ARZSUMO_CACHE", "~/.cache/arzsumo", "ARZSUMO_SUMO_NETS", "arzsumo/data/sumo_nets",
                 "0    done", "2    user error", "3    the PDE twin left", "4    some sweep",
                 "130  interrupted", "arzsumo list"):
        assert text in top, text
    assert main(["verify", "--help"]) == 0
    verify = " ".join(capsys.readouterr().out.split())
    assert "run length, s (default: 450.0)" in verify and "(default: 200)" in verify
    assert "(default: None)" not in verify and "(default: False)" not in verify
    assert main(["run", "--help"]) == 0
    run = " ".join(capsys.readouterr().out.split())
    assert "--dry-run" in run and "(default: [sumo] horizon_s)" in run


def test_list_shows_shipped_names_and_where_they_run(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert "scenarios/" not in out and ".toml" not in out      # names, not package paths
    lines = out.splitlines()
    sumo = lines.index(next(x for x in lines if x.startswith("SUMO scenarios")))
    twin = lines.index(next(x for x in lines if x.startswith("twin-only scenarios")))
    assert sumo < lines.index(next(x for x in lines if x.split()[:1] == ["default"])) < twin
    assert lines.index(next(x for x in lines if x.split()[:1] == ["paper_base"])) > twin
    assert "One coupled mixed stream in SUMO, congested by the merge (fill" in out
    assert any(x.split()[:1] == ["lateral_files"] for x in lines)
    assert any(x.split()[:2] == ["penetration_twin", "[twin]"] for x in lines)
    assert main(["list", "--json"]) == 0
    files = json.loads(capsys.readouterr().out)
    data = ROOT / "src" / "arzsumo" / "data"      # the package's own copy (shipped)
    shipped = {p.relative_to(ROOT).as_posix() for p in (data / "scenarios").rglob("*.toml")}
    assert {f["path"] for f in files} == shipped
    assert all(f["description"] for f in files)         # every shipped file says what it is
    groups = {f["name"]: f["group"] for f in files}
    assert groups["demand_sumo"].startswith("sweeps") and groups["base_etc"].startswith("paper")
    where = {f["name"]: f["runs_in"] for f in files}
    assert where["default"] == where["legacy_default"] == where["demand_sumo"] == "sumo"
    assert where["paper_base"] == where["base_etc"] == where["penetration_twin"] == "twin"
    assert len(groups) == len(files)                    # every name is one file
