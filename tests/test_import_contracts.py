"""The import contracts of ``pyproject.toml`` ([tool.importlinter]) hold, and they bite: a
copy of the package with one wrong arrow added fails ``lint-imports``."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "pyproject.toml"
PACKAGE = ROOT / "src" / "arzsumo"
RESEARCH = ROOT / "research" / "src" / "arzsumo_studies"


def _lint(src: Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    """Run lint-imports with the project's contracts on the packages found under ``src``
    (the tool, ``arzsumo``, and the research, ``arzsumo_studies``)."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    code = "from importlinter.cli import lint_imports_command; lint_imports_command()"
    return subprocess.run([sys.executable, "-c", code, str(CONFIG), "--no-cache"],
                          cwd=cwd, env=env, capture_output=True, text=True, timeout=120)


def _copy(tmp_path: Path) -> Path:
    src = tmp_path / "src"
    for package in (PACKAGE, RESEARCH):
        shutil.copytree(package, src / package.name,
                        ignore=shutil.ignore_patterns("__pycache__"))
    return src


def test_the_package_keeps_every_contract(tmp_path):
    res = _lint(_copy(tmp_path), tmp_path)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "8 kept, 0 broken" in res.stdout


@pytest.mark.parametrize(("where", "line", "contract"), [
    # the math reaching for SUMO, and the twin numerics for a file writer
    ("model/_wrong.py", "import arzsumo.sumo.simulation\n",
     "The math (model, control, twin numerics, estimation) imports no SUMO"),
    ("pde/flux.py", "from arzsumo.io import json_safe\n",
     "The math (model, control, twin numerics, estimation) imports no SUMO"),
    # the estimator reaching for the SUMO bridge's measurements
    ("estimate/_wrong.py", "import arzsumo.bridge.estimator\n",
     "The math (model, control, twin numerics, estimation) imports no SUMO"),
    # a library room drawing a figure itself (lazily, as twin/output.py once did)
    ("bridge/_wrong.py", "def f():\n    import arzsumo.plots.bridge\n",
     "Only the output layer imports plots"),
    # a plot saving its own file
    ("plots/twin.py", "from arzsumo.io import atomic_file\n",
     "Plots draw and return Figures; only the output layer writes files"),
    # plots reaching up into the runs
    ("plots/_wrong.py", "import arzsumo.sweep.spec\n", "Rooms import only downward"),
    # SUMO's own modules outside the SUMO side, at import time or lazily
    ("workflows/_wrong.py", "import libsumo\n", "Only the SUMO side imports libsumo"),
    ("bridge/_wrong.py", "def f():\n    import traci\n", "Only the SUMO side imports libsumo"),
    ("cli/_wrong.py", "from sumolib.net import readNet\n",
     "Only the SUMO side imports libsumo"),
    # the tool reaching for the research, at import time or lazily
    ("sweep/_wrong.py", "import arzsumo_studies.recorded\n",
     "The tool never imports the research package"),
    ("cli/run.py", "def f():\n    import arzsumo_studies.cli.catalog\n",
     "The tool never imports the research package"),
    # one family of studies reaching into another, and the shared machinery up into one
    ("../arzsumo_studies/control/_wrong.py", "import arzsumo_studies.premise.map_points\n",
     "Families of studies are independent of each other"),
    ("../arzsumo_studies/design.py",
     "def f():\n    import arzsumo_studies.ablation.steps\n",
     "Families of studies are independent of each other"),
])
def test_a_wrong_import_breaks_its_contract(tmp_path, where, line, contract):
    src = _copy(tmp_path)
    path = src / "arzsumo" / where                 # a new module, or one line appended
    path.write_text((path.read_text(encoding="utf-8") if path.exists() else "") + line,
                    encoding="utf-8")
    res = _lint(src, tmp_path)
    assert res.returncode != 0
    assert f"{contract}" in res.stdout and "BROKEN" in res.stdout
    module = where.removesuffix(".py").replace("../", "").replace("/", ".")
    assert (module if where.startswith("../") else "arzsumo." + module) in res.stdout
