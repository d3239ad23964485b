"""labstand: runs the fibre stand, records it, and diagnoses the sim-to-real gap."""

from __future__ import annotations

from typing import Any

__all__ = ["__version__"]


def __getattr__(name: str) -> Any:
    # importlib.metadata (which imports email, ~20 ms) only when the version is asked for
    if name != "__version__":
        raise AttributeError(f"module 'labstand' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("labstand")
    except PackageNotFoundError:  # running from a source tree that was not installed
        return "0+unknown"
