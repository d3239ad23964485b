"""Where the live Foxglove server listens: ``--foxglove [HOST:]PORT``.

Loopback unless a host is given; any other address is taken only when spelled out, and
a warning says the stand's data is then open to the network (the server has no
authentication).
"""

from __future__ import annotations

import ipaddress
import logging
from dataclasses import dataclass

log = logging.getLogger(__name__)

__all__ = ["ViewerAddress", "parse_address"]

LOOPBACK = "127.0.0.1"


@dataclass(frozen=True)
class ViewerAddress:
    """A host and a TCP port (0: any free port) for the live server."""

    host: str
    port: int

    @property
    def loopback(self) -> bool:
        """True if only this machine can connect."""
        if self.host == "localhost":
            return True
        try:
            return ipaddress.ip_address(self.host).is_loopback
        except ValueError:
            return False

    def __str__(self) -> str:
        return f"{self.host}:{self.port}"


def parse_address(text: str) -> ViewerAddress:
    """``PORT`` (on loopback) or ``HOST:PORT``; ValueError naming the value if bad."""
    host, sep, port_text = text.rpartition(":")
    if not sep:
        host = LOOPBACK
    host = host.strip("[]")  # [::1]:8765
    if not host:
        raise ValueError(f"--foxglove {text!r}: no host before ':'; give PORT or HOST:PORT")
    try:
        port = int(port_text)
    except ValueError:
        raise ValueError(f"--foxglove {text!r}: the port must be a number (0-65535)") from None
    if not 0 <= port <= 65535:
        raise ValueError(f"--foxglove {text!r}: port {port} is out of range 0-65535")
    address = ViewerAddress(host, port)
    if not address.loopback:
        log.warning(
            "the Foxglove server listens on %s, open to the network (no authentication)",
            address,
        )
    return address
