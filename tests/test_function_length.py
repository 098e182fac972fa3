"""No function in ``src/arzsumo`` is over 60 lines.

A function's length is counted from its ``def`` line to its last line, docstring included
(decorators excluded), as ``ast`` reports them.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "arzsumo"

#: Limit (lines): a longer function fails the suite.
MAX_LINES = 60


def function_lengths(source: str, name: str = "<string>") -> list[tuple[int, str]]:
    """(lines, "name:lineno:function") of every function and method in ``source``."""
    rows = []
    for node in ast.walk(ast.parse(source, name)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            assert node.end_lineno is not None
            rows.append((node.end_lineno - node.lineno + 1, f"{name}:{node.lineno}:{node.name}"))
    return rows


def package_lengths() -> list[tuple[int, str]]:
    """Lengths of every function of the package, longest first."""
    rows = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parents[1]).as_posix()
        rows += function_lengths(path.read_text(encoding="utf-8"), rel)
    return sorted(rows, reverse=True)


def test_the_measure_counts_def_to_last_line_and_nested_functions():
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_LINES - 1))
    source = f'def long():\n    """Doc."""\n{body}\n\n\nclass C:\n    def m(self):\n' \
             "        def inner():\n            return 1\n        return inner\n"
    rows = dict((where.split(":")[-1], n) for n, where in function_lengths(source))
    assert rows == {"long": MAX_LINES + 1, "m": 4, "inner": 2}
    assert [n for n, _ in function_lengths(source) if n > MAX_LINES] == [MAX_LINES + 1]


def test_the_package_has_functions_to_measure():
    rows = package_lengths()
    assert len(rows) > 300
    assert any(where.endswith(":solve_kernels") for _, where in rows)


def test_no_function_is_over_60_lines():
    over = [f"{n} {where}" for n, where in package_lengths() if n > MAX_LINES]
    assert over == [], f"functions over {MAX_LINES} lines: {over}"
