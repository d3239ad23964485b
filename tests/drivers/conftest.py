"""Driver tests fail when they leave threads, descriptors or processes behind."""

from tests.hardware_sim.leakcheck import no_leaks

__all__ = ["no_leaks"]
