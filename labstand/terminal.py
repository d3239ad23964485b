r"""Text from files and users, made safe for a terminal.

A recording's note, host, event texts and metadata are whatever their writer put there:
an escape sequence in a note (``--note $'\e]0;…\a'``) would retitle, recolour or
rewrite the terminal of whoever runs ``labstand info`` on the file.
"""

from __future__ import annotations

__all__ = ["printable"]


def printable(text: str) -> str:
    """``text`` with every non-printable character (ESC, BEL, CR, ...) shown escaped."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
