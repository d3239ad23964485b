"""Exit codes of the labstand command and the errors that map onto them.

Every expected failure reaches the user as one line on stderr and a non-zero exit
code, never as a traceback.
"""

from __future__ import annotations

import errno
from enum import IntEnum
from pathlib import Path


class ExitCode(IntEnum):
    """What ``labstand`` returns."""

    OK = 0
    FAILURE = 1  # a device, a file or a run failed
    USAGE = 2  # bad arguments or bad input files (argparse uses 2 as well)
    REFUSED = 3  # a command beyond the stand's limits: nothing moved
    ESTOP = 4  # a run ended in an emergency stop (recording closed and readable)
    INTERRUPTED = 130  # Ctrl-C (SIGINT)
    TERMINATED = 143  # SIGTERM (128 + 15, as a shell reports a process it ended)


class CommandError(Exception):
    """A failure a command reports as one line, with its exit code."""

    def __init__(self, message: str, code: ExitCode = ExitCode.FAILURE) -> None:
        super().__init__(message)
        self.code = code


#: OS errors on an input, in words (the errno text, ``[Errno 2] ...``, is Python's).
_OS_WORDS: dict[type[OSError], tuple[str, ExitCode]] = {
    FileNotFoundError: ("no such file", ExitCode.USAGE),
    IsADirectoryError: ("is a folder, not a file", ExitCode.USAGE),
    NotADirectoryError: ("a part of the path is not a folder", ExitCode.USAGE),
    PermissionError: ("permission denied", ExitCode.FAILURE),
}


def describe_os_error(err: OSError) -> tuple[str, ExitCode]:
    """An OSError as one worded line and its exit code (a missing input is bad input, 2)."""
    for kind, (words, code) in _OS_WORDS.items():
        if isinstance(err, kind) and err.filename is not None:
            name = str(err.filename)
            return (
                f"no such file: {name}" if kind is FileNotFoundError else f"{name}: {words}"
            ), code
    if err.strerror and err.filename is not None:
        return f"{err.filename}: {err.strerror[:1].lower()}{err.strerror[1:]}", ExitCode.FAILURE
    if err.strerror:
        return err.strerror, ExitCode.FAILURE
    return str(err), ExitCode.FAILURE


def require_file(path: Path) -> None:
    """Raise the worded OSError for an input that is missing or a folder."""
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a folder", str(path))
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "no such file", str(path))
