"""arzsumo: PDE boundary control of mixed-autonomy traffic, from the ARZ model into SUMO."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("arzsumo")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
