"""Where the SUMO binaries and the shipped network live.

The binaries come from the ``eclipse-sumo`` wheel (``sumo.SUMO_HOME/bin``). The network
ships inside the package (:mod:`arzsumo.resources`); ``ARZSUMO_SUMO_NETS`` or an explicit
argument overrides it (docs/sumo.md, "Network"). SUMO's temporary files (route, detector
and statistics files) go under :func:`scratch_dir`.
"""

from __future__ import annotations

import os
from pathlib import Path

from arzsumo.errors import ArzsumoError
from arzsumo.outdir import SCRATCH_ENV
from arzsumo.resources import shipped_nets_dir

#: Environment variable that overrides the network directory.
NETS_ENV = "ARZSUMO_SUMO_NETS"


#: File names inside a network directory.
NET_FILE = "ramp.net.xml"
ROUTE_FILE = "ramp.rou.xml"
CONFIG_FILE = "ramp.sumocfg"


class SumoError(ArzsumoError, RuntimeError):
    """SUMO could not be found, started or stepped; the message is SUMO's cause in one line."""


def sumo_home() -> Path:
    """SUMO_HOME of the installed ``eclipse-sumo`` wheel."""
    try:
        import sumo
    except ImportError:  # pragma: no cover - a dependency of the package
        raise SumoError("the eclipse-sumo package is not installed; allowed: "
                        "pip install eclipse-sumo") from None
    return Path(sumo.SUMO_HOME)


def sumo_binary(name: str) -> Path:
    """Path of a packaged SUMO binary (``sumo``, ``netconvert``, ``sumo-gui``...)."""
    path = sumo_home() / "bin" / name
    if not path.exists():
        raise SumoError(f"binary = {name!r} is not in {path.parent}; allowed: "
                        f"{', '.join(sorted(p.name for p in path.parent.iterdir()))}")
    return path


def default_nets_dir() -> Path:
    """The network directory: ``$ARZSUMO_SUMO_NETS`` or the one shipped in the package."""
    env = os.environ.get(NETS_ENV)
    return Path(env) if env else shipped_nets_dir()


def build_nets_dir(override: str | os.PathLike[str] | None = None) -> Path:
    """Where ``arzsumo build-net`` writes: ``override``, ``$ARZSUMO_SUMO_NETS``, or the
    shipped directory when it belongs to a source checkout.

    An installed package's files are not the user's to rewrite (a reinstall would undo the
    change silently), so an installed or read-only shipped directory is refused.
    """
    if override is not None:
        return Path(override)
    path = default_nets_dir()
    if not os.environ.get(NETS_ENV):
        refuse_installed_nets(path)
    return path


def refuse_installed_nets(path: Path) -> None:
    """Raise SumoError if ``path`` is inside an installed package or not writable."""
    installed = any(part in ("site-packages", "dist-packages") for part in path.parts)
    if installed or not os.access(path, os.W_OK):
        why = "is inside the installed package" if installed else "is not writable"
        raise SumoError(f"network directory {str(path)!r} {why}; allowed: "
                        f"`arzsumo build-net --out DIR` or {NETS_ENV}=DIR")


def nets_dir(override: str | os.PathLike[str] | None = None) -> Path:
    """The network directory to use, checked to hold a built network."""
    path = Path(override) if override is not None else default_nets_dir()
    if not (path / NET_FILE).is_file():
        raise SumoError(f"net_dir = {str(path)!r} holds no {NET_FILE}; allowed: a directory "
                        "written by `arzsumo build-net` (or set ARZSUMO_SUMO_NETS)")
    return path


def scratch_dir() -> Path | None:
    """Where SUMO's temporary files go: ``$ARZSUMO_SCRATCH_DIR`` (created if missing), or
    None for the system's temporary directory."""
    env = os.environ.get(SCRATCH_ENV)
    if not env:
        return None
    path = Path(env)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:  # the run that set it is gone: fall back rather than fail
        return None
    return path
