"""Nothing outside ``arzsumo.sumo`` reaches the open run's module (libsumo or traci, the
``lib`` of :class:`~arzsumo.sumo.simulation.SumoSimulation` and of the readers built on it):
what a study or the bridge needs from SUMO is read inside ``sumo/`` and handed out as data
(:meth:`arzsumo.sumo.plant.SumoPlant.run_open_loop`). The import contract keeps the modules
themselves in ``sumo/``; this keeps the handle there."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "arzsumo"
#: attribute names under which the open run's module is held
HANDLES = {"lib", "_lib"}


def handle_uses(source: str, name: str = "<string>") -> list[str]:
    """``name:line`` of every attribute access ``<anything>.lib`` (or ``._lib``) in
    ``source``, and of every ``getattr`` that names one."""
    found: list[int] = []
    for node in ast.walk(ast.parse(source, name)):
        attribute = isinstance(node, ast.Attribute) and node.attr in HANDLES
        named = (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                 and node.func.id == "getattr" and len(node.args) >= 2
                 and isinstance(node.args[1], ast.Constant) and node.args[1].value in HANDLES)
        if attribute or named:
            found.append(node.lineno)
    return [f"{name}:{line}" for line in sorted(found)]


def test_the_scan_finds_the_handle_however_it_is_reached():
    source = ("def f(sim, plant):\n    sim.lib.edge.getIDList()\n    x = plant.sim.lib\n"
              "    y = getattr(sim, 'lib')\n    return sim.library, x, y\n")
    assert handle_uses(source) == ["<string>:2", "<string>:3", "<string>:4"]


def test_no_module_outside_the_sumo_side_reaches_the_simulation_handle():
    outside = [p for p in sorted(PACKAGE.rglob("*.py"))
               if p.relative_to(PACKAGE).parts[0] != "sumo"]
    assert len(outside) > 150       # the whole package but sumo/ was scanned
    found = [use for p in outside for use in handle_uses(
        p.read_text(encoding="utf-8"), p.relative_to(PACKAGE.parent).as_posix())]
    assert found == [], f"the raw SUMO handle outside arzsumo.sumo: {found}"
