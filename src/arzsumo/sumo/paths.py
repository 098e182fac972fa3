"""Where the SUMO binaries and the shipped network live.

The binaries come from the ``eclipse-sumo`` wheel (``sumo.SUMO_HOME/bin``). The network
directory ``sumo_nets/`` sits at the repository root; the environment variable
``ARZSUMO_SUMO_NETS`` or an explicit argument overrides it. SUMO's temporary files (route,
detector and statistics files) go under :func:`scratch_dir`.
"""

from __future__ import annotations

import os
from pathlib import Path

from arzsumo.errors import ArzsumoError
from arzsumo.outdir import SCRATCH_ENV

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
    """The network directory: ``$ARZSUMO_SUMO_NETS`` or ``sumo_nets/`` at the repository root."""
    env = os.environ.get(NETS_ENV)
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3] / "sumo_nets"


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
