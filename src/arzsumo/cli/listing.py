"""``arzsumo list``: the shipped scenario and sweep files by name, with their descriptions,
split by where they run (SUMO or the twin only)."""

from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

from arzsumo.cli.options import add_json
from arzsumo.resources import shipped_scenarios_dir

#: (group, directory under the shipped scenarios) in the order they are listed
GROUPS = (("scenarios", "."), ("paper experiments (arzsumo reproduce)", "paper"),
          ("sweeps (arzsumo sweep)", "sweeps"))
#: headings of the text listing: (group, runs_in or None for any, heading)
HEADINGS = (("scenarios", "sumo", "SUMO scenarios, with a [sumo] table (arzsumo run NAME; "
                                  "the twin runs them too):"),
            ("scenarios", "twin", "twin-only scenarios, no [sumo] table (arzsumo twin NAME):"),
            (GROUPS[1][0], None, "paper experiments, twin only (arzsumo reproduce; arzsumo "
                                 "twin NAME):"),
            (GROUPS[2][0], None, "sweeps (arzsumo sweep NAME), with their engine:"))

def _read(path: Path) -> dict | None:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError:
        return None


def describe(path: Path) -> str:
    """The file's ``description`` key, else its first comment line, else ``""``."""
    data = _read(path)
    if data is None:
        return "(not valid TOML)"
    desc = data.get("description")
    if isinstance(desc, str) and desc.strip():
        return desc.strip()
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            return line.lstrip("#").strip()
    return ""


def runs_in(path: Path, sub: str) -> str:
    """Where a shipped file runs: a sweep's ``engine``; a scenario ``"sumo"`` when it has
    a ``[sumo]`` table, else ``"twin"``."""
    data = _read(path) or {}
    if sub == "sweeps":
        return str(data.get("engine", "twin"))
    return "sumo" if isinstance(data.get("sumo"), dict) else "twin"


def _shown(path: Path) -> str:
    """``path`` relative to the working directory when below it, else absolute."""
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def shipped() -> list[dict[str, str]]:
    """Every shipped file: group, path, name (what commands take), description, runs_in."""
    root = shipped_scenarios_dir()
    return [{"group": group, "path": _shown(f), "name": f.stem, "description": describe(f),
             "runs_in": runs_in(f, sub)}
            for group, sub in GROUPS for f in sorted((root / sub).glob("*.toml"))]


def cmd_list(args: argparse.Namespace) -> int:
    files = shipped()
    if args.json:
        print(json.dumps(files, indent=2))
        return 0
    if not files:
        print(f"no scenario files under {shipped_scenarios_dir()}")
        return 0
    for group, where, heading in HEADINGS:
        rows = [f for f in files if f["group"] == group and where in (None, f["runs_in"])]
        if not rows:
            continue
        names = [f"{f['name']} [{f['runs_in']}]" if group == GROUPS[2][0] else f["name"]
                 for f in rows]
        width = max(map(len, names))
        print(heading)
        for name, f in zip(names, rows, strict=True):
            print(f"  {name:<{width}}  {f['description']}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``list`` to the top-level parser."""
    p = sub.add_parser("list", help="list the shipped scenario and sweep files",
                       description="List by name the scenario files (those for SUMO and "
                                   "those for the PDE twin only), the paper's experiments "
                                   "and the sweep files shipped with the package, with their "
                                   "descriptions (the description key or the first comment "
                                   "line). Commands take a name in place of a file.")
    add_json(p, "print JSON (group, path, name, description, runs_in)")
    p.set_defaults(func=cmd_list)
