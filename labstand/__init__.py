"""labstand: runs the fibre stand, records it, and diagnoses the sim-to-real gap."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("labstand")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
