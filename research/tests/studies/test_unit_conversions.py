"""The studies convert units through :mod:`arzsumo.units` only: no factor 3.6, 1000 or
3600 multiplies or divides a quantity in ``research/src/arzsumo_studies``."""

from __future__ import annotations

import ast
from pathlib import Path

STUDIES = Path(__file__).resolve().parents[2] / "src" / "arzsumo_studies"

#: km/h per m/s, veh/km per veh/m (and m per km), s per h
FACTORS = {3.6, 1000, 3600}


def literal_conversions(source: str, name: str = "<string>") -> list[str]:
    """``name:lineno`` of every product or quotient with a literal unit factor."""
    found = []
    for node in ast.walk(ast.parse(source, name)):
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult | ast.Div):
            for side in (node.left, node.right):
                if isinstance(side, ast.Constant) and type(side.value) in (int, float) \
                        and side.value in FACTORS:
                    found.append((node.lineno, f"{name}:{node.lineno}"))
    return [where for _, where in sorted(found)]


def test_the_check_finds_a_factor_in_code_and_in_an_f_string_but_not_in_text():
    source = 'a = v * 3.6\nb = f"{q * 3600:.0f} veh/h"\nc = 1 / 1000\n"""x * 3.6"""\nd = 3600'
    assert literal_conversions(source) == ["<string>:1", "<string>:2", "<string>:3"]


def test_no_study_converts_units_with_a_literal_factor():
    found = []
    for path in sorted(STUDIES.rglob("*.py")):
        found += literal_conversions(path.read_text(encoding="utf-8"),
                                     path.relative_to(STUDIES).as_posix())
    assert found == [], "use arzsumo.units for: " + ", ".join(found)


def test_vehicle_seconds_become_vehicle_hours():
    from arzsumo.units import S_PER_H, s_to_h

    assert s_to_h(7200.0) == 2.0 and s_to_h([S_PER_H, 0.0]).tolist() == [1.0, 0.0]
