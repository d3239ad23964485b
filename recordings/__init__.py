"""Recordings: formats (MCAP, HDF5), import, replay and comparison."""

__all__: list[str] = []
