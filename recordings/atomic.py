"""Files written under a temporary name and renamed when complete.

A crash or a failed write leaves no stub under the user's name; and an error names the
user's path, never the temporary one (which the user never asked for).
"""

from __future__ import annotations

import contextlib
import errno
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from recordings.errors import RecordingError

__all__ = ["written_whole"]


@contextmanager
def written_whole(path: Path, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary sibling of ``path`` to write; rename it to ``path`` on success.

    ``suffix`` is appended to the temporary name (writers that pick their format by the
    suffix need ``path``'s own). Any OSError (no such folder, disk full, no permission)
    becomes ``OSError("PATH: cannot write: reason")``, a RecordingError that names the
    temporary file names ``path`` instead; the temporary file is removed.
    """
    tmp = path.with_name(path.name + ".part" + suffix)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as err:
        raise OSError(f"{path}: cannot write: {_reason(path, tmp, err)}") from err
    except RecordingError as err:  # a writer's check names the file it writes: the user's
        if str(tmp) not in str(err):
            raise
        raise type(err)(str(err).replace(str(tmp), str(path))) from err
    finally:
        with contextlib.suppress(OSError):  # never there, or its folder is not one
            tmp.unlink(missing_ok=True)


def _reason(path: Path, tmp: Path, err: OSError) -> str:
    parent = path.parent
    if not parent.is_dir():
        return f"no such folder {parent}" if not parent.exists() else f"{parent} is not a folder"
    if err.errno is not None and err.errno in errno.errorcode:
        return os.strerror(err.errno)
    return str(err).replace(str(tmp), str(path))  # e.g. h5py's own wording, without errno
