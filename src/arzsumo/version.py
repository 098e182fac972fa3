"""The package's version (what every result records beside its resolved scenario)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("arzsumo")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
