"""The one registry of controllers: every list of names comes from it."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from arzsumo.cli import build_parser
from arzsumo.control.registry import controller_names, is_pde, pde_controller_names

SRC = Path(__file__).resolve().parents[2] / "src" / "arzsumo"


def _choices(parser: argparse.ArgumentParser, command: str, option: str) -> list[str]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    action = next(a for a in sub.choices[command]._actions if option in a.option_strings)
    return list(action.choices)


def test_cli_choices_are_the_registry_names():
    parser = build_parser()
    assert _choices(parser, "run", "--controller") == list(controller_names("sumo"))
    assert _choices(parser, "verify", "--controller") == ["theory", *pde_controller_names()]
    assert controller_names("sumo") == ("open", "backstepping", "etc", "observer-etc",
                                        "constant", "alinea", "pi-alinea", "held")
    assert controller_names("twin") == ("open", "backstepping", "etc", "observer-etc",
                                        "constant")
    assert [n for n in controller_names() if is_pde(n)] == ["backstepping", "etc",
                                                             "observer-etc"]


def test_no_other_list_of_controllers_no_raw_scenario_no_assert_in_src():
    for path in SRC.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        rel = path.relative_to(SRC)
        assert not re.search(r"^\s*assert\b", text, re.M), rel
        assert not re.search(r"\.raw\b", text), rel
        if rel == Path("control/registry.py"):
            continue
        code = "\n".join(line for line in text.splitlines()
                         if not line.lstrip().startswith("#"))
        assert not re.search(r"CONTROLLERS\s*[:=]", code), rel
        assert not re.search(r'[(\[]"(open|theory)", "backstepping"', code), rel
