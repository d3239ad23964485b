"""One mixin for everything that must be closed however a ``with`` block ends.

Devices, recording writers, the run's recording pipe and its display all release
something in ``close()`` (a drive disables itself, a file is finalised); ``with`` calls
it on every way out, exceptions included.
"""

from __future__ import annotations

from types import TracebackType
from typing import Self

__all__ = ["ClosesOnExit"]


class ClosesOnExit:
    """``__enter__`` returns self; ``__exit__`` calls ``close()``, which subclasses define."""

    def close(self) -> None:
        """Release what the object holds (subclasses; idempotent)."""
        raise NotImplementedError

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
