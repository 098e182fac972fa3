"""``benchmarks/`` holds benchmarks only (``bench_*.py``; the studies live in
:mod:`arzsumo_studies`), and every benchmark prints a ratio: against a reference, the
bare component or real time."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
FILES = sorted(BENCHMARKS.glob("*.py"))


def printed_text(path: Path) -> str:
    """The literal text of every ``print(...)`` call in ``path``."""
    parts = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print":
            parts += [c.value for arg in node.args for c in ast.walk(arg)
                      if isinstance(c, ast.Constant) and isinstance(c.value, str)]
    return " ".join(parts)


def test_benchmarks_holds_only_benchmarks():
    assert FILES, "no benchmarks found"
    assert [p.name for p in FILES if not p.name.startswith("bench_")] == []


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_every_benchmark_prints_a_ratio(path):
    assert re.search(r"ratio|speed-up", printed_text(path)), \
        f"{path.name} prints no ratio (against a reference, the bare component or real time)"


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_benchmarks_name_no_issue_numbers_and_edit_no_sys_path(path):
    text = path.read_text(encoding="utf-8")
    assert not re.search(r"\bissues? \d", text, re.IGNORECASE)
    assert "sys.path" not in text
