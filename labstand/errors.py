"""Exit codes of the labstand command and the errors that map onto them.

Every expected failure reaches the user as one line on stderr and a non-zero exit
code, never as a traceback.
"""

from __future__ import annotations

from enum import IntEnum


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
