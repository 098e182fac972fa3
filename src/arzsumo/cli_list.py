"""``arzsumo list``: the shipped scenario and sweep files, with their descriptions."""

from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

from arzsumo.resources import shipped_scenarios_dir

#: (group, directory under the shipped scenarios) in the order they are listed
GROUPS = (("scenarios", "."), ("paper experiments (arzsumo reproduce)", "paper"),
          ("sweeps (arzsumo sweep)", "sweeps"))


def describe(path: Path) -> str:
    """The file's ``description`` key, else its first comment line, else ``""``."""
    text = path.read_text(encoding="utf-8")
    try:
        desc = tomllib.loads(text).get("description")
    except tomllib.TOMLDecodeError:
        return "(not valid TOML)"
    if isinstance(desc, str) and desc.strip():
        return desc.strip()
    for line in text.splitlines():
        if line.startswith("#"):
            return line.lstrip("#").strip()
    return ""


def _shown(path: Path) -> str:
    """``path`` relative to the working directory when below it, else absolute."""
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def shipped(root: Path | None = None) -> list[dict[str, str]]:
    """Every shipped file: group, path, name (stem) and description."""
    root = shipped_scenarios_dir() if root is None else root
    return [{"group": group, "path": _shown(f), "name": f.stem, "description": describe(f)}
            for group, sub in GROUPS for f in sorted((root / sub).glob("*.toml"))]


def cmd_list(args: argparse.Namespace) -> int:
    files = shipped()
    if args.json:
        print(json.dumps(files, indent=2))
        return 0
    if not files:
        print(f"no scenario files under {shipped_scenarios_dir()}")
        return 0
    width = max(len(f["path"]) for f in files)
    for group, _ in GROUPS:
        print(f"{group}:")
        for f in (f for f in files if f["group"] == group):
            print(f"  {f['path']:<{width}}  {f['description']}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``list`` to the top-level parser."""
    p = sub.add_parser("list", help="list the shipped scenario and sweep files",
                       description="List the scenario files, the paper's experiments and "
                                   "the sweep files shipped with the package, with their "
                                   "descriptions (the description key or the first comment "
                                   "line).")
    p.add_argument("--json", action="store_true",
                   help="print JSON (group, path, name, description)")
    p.set_defaults(func=cmd_list)
