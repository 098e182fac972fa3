"""The wheel ships the network and the scenario files, and a non-editable install runs.

The wheel is built offline from a copy of the source tree (``pip wheel
--no-build-isolation``, which needs the ``wheel`` package of the ``test`` extra, or
setuptools 70.1 or later). The install test puts it into a fresh venv that reaches the
dependencies through a ``.pth`` line to the running venv's site-packages, never the
project's ``src/`` (a ``.pth`` found there is not processed), and runs ``arzsumo`` from
another directory.
"""

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from importlib.metadata import version
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "src" / "arzsumo" / "data"
PKG_DATA = "arzsumo/data"


def _can_build() -> bool:
    setuptools = tuple(int(p) for p in version("setuptools").split(".")[:2])
    return importlib.util.find_spec("wheel") is not None or setuptools >= (70, 1)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    if not (ROOT / "pyproject.toml").is_file():
        pytest.skip("needs a source checkout")
    if not _can_build():
        pytest.skip("building a wheel offline needs the wheel package: "
                    "pip install -e '.[test]'")
    tree = tmp_path_factory.mktemp("tree")
    # a copy, so that build/ and *.egg-info never land in the checkout (nor stale files in
    # the wheel)
    shutil.copytree(ROOT / "src", tree / "src",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, tree / name)
    dist = tmp_path_factory.mktemp("dist")
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", str(tree), "--no-deps",
                           "--no-build-isolation", "--no-index", "--quiet", "-w", str(dist)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    (whl,) = dist.glob("arzsumo-*.whl")
    return whl


def test_wheel_holds_the_network_and_every_scenario_and_sweep_file(wheel):
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        for net in ("ramp.net.xml", "ramp.rou.xml", "ramp.sumocfg", "ramp.tll.xml"):
            assert f"{PKG_DATA}/sumo_nets/{net}" in names
        shipped = {f"{PKG_DATA}/{p.relative_to(DATA).as_posix()}"
                   for p in DATA.rglob("*") if p.is_file() and not p.name.startswith(".")}
        assert shipped <= names
        assert sum(n.startswith(f"{PKG_DATA}/scenarios/sweeps/") for n in names) == 9
        assert z.read(f"{PKG_DATA}/scenarios/default.toml") == \
            (DATA / "scenarios" / "default.toml").read_bytes()
        entry = next(n for n in names if n.endswith(".dist-info/entry_points.txt"))
        assert "arzsumo = arzsumo.cli:main" in z.read(entry).decode()


def _fresh_venv(tmp_path: Path, wheel: Path) -> Path:
    """A venv holding only the installed wheel; the dependencies come from this venv."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True,
                   timeout=120)
    python = venv / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install",
                    "--no-deps", "--no-index", "--quiet", str(wheel)], check=True, timeout=300)
    # after the install, so that pip never sees (nor touches) this venv's own arzsumo
    site = subprocess.run([str(python), "-c", "import sysconfig; "
                           "print(sysconfig.get_paths()['purelib'])"], check=True,
                          capture_output=True, text=True).stdout.strip()
    deps = {sysconfig.get_paths()[k] for k in ("purelib", "platlib")}
    (Path(site) / "_arzsumo_test_deps.pth").write_text("\n".join(sorted(deps)) + "\n")
    return venv


@pytest.mark.slow
@pytest.mark.sumo
def test_installed_wheel_runs_from_another_directory(wheel, tmp_path):
    venv = _fresh_venv(tmp_path, wheel)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "ARZSUMO_SUMO_NETS")}
    env["ARZSUMO_CACHE"] = str(tmp_path / "cache")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    where = subprocess.run([str(venv / "bin" / "python"), "-c",
                            "import arzsumo; print(arzsumo.__file__)"], cwd=elsewhere, env=env,
                           capture_output=True, text=True, check=True).stdout.strip()
    assert Path(where).is_relative_to(venv)
    proc = subprocess.run([str(venv / "bin" / "arzsumo"), "run", "--horizon", "30",
                           "--warmup", "30", "--allow-short-warmup", "--quiet", "--no-plots",
                           "--out", "r"],
                          cwd=elsewhere, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    summ = json.loads((elsewhere / "r" / "summary.json").read_text())
    assert summ["complete"] and summ["horizon"] == 30.0 and summ["scenario"] == "default"
    assert Path(summ["source"]).is_relative_to(venv)
    assert summ["q_nominal"] == pytest.approx(4464 / 3600)
    nets = Path(where).parent / "data" / "sumo_nets"
    before = sorted(p.name for p in nets.iterdir())
    proc = subprocess.run([str(venv / "bin" / "arzsumo"), "build-net"], cwd=elsewhere,
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "is inside the installed package" in proc.stderr
    assert sorted(p.name for p in nets.iterdir()) == before
