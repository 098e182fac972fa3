"""Exit codes have one definition each (:mod:`arzsumo.errors`, the signals' in
:mod:`arzsumo.interrupts`), and the commands and studies return them by name."""

from __future__ import annotations

import ast
from pathlib import Path

from arzsumo import errors

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "arzsumo"


def _modules() -> list[tuple[str, ast.Module]]:
    return [(p.relative_to(PACKAGE).as_posix(), ast.parse(p.read_text(encoding="utf-8")))
            for p in sorted(PACKAGE.rglob("*.py"))]


def literal_exit_codes(tree: ast.Module, name: str = "<string>") -> list[str]:
    """``name:lineno`` of every ``return`` of a non-zero integer literal, alone or as a
    branch of ``A if C else B``."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Return) or node.value is None:
            continue
        values = [node.value.body, node.value.orelse] if isinstance(node.value, ast.IfExp) \
            else [node.value]
        if any(isinstance(v, ast.Constant) and type(v.value) is int and v.value != 0
               for v in values):
            found.append(f"{name}:{node.lineno}")
    return found


def test_the_check_finds_a_literal_code_alone_or_in_a_choice():
    tree = ast.parse("def a():\n    return 4 if bad else 0\ndef b():\n    return 0\n"
                     "def c():\n    return EXIT_SOME_FAILED if bad else 0\ndef d():\n"
                     "    return 3\n")
    assert literal_exit_codes(tree) == ["<string>:2", "<string>:8"]


def test_commands_and_studies_return_exit_codes_by_name():
    found = [hit for name, tree in _modules() if name.startswith(("cli/", "studies/"))
             for hit in literal_exit_codes(tree, name)]
    assert found == [], "return the arzsumo.errors constant instead: " + ", ".join(found)


def test_each_exit_code_is_defined_once():
    defined: dict[str, list[str]] = {}
    for name, tree in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.Assign):
                for target in node.targets:
                    names = target.elts if isinstance(target, ast.Tuple) else [target]
                    for n in names:
                        if isinstance(n, ast.Name) and n.id.startswith("EXIT_"):
                            defined.setdefault(n.id, []).append(name)
    assert {k: v for k, v in defined.items() if len(v) > 1} == {}
    assert {k for k, v in defined.items() if v == ["errors.py"]} == \
        {k for k in vars(errors) if k.startswith("EXIT_")}
