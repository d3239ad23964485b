"""python -m labstand."""

from labstand.cli import entry_point

entry_point()
