"""The live Foxglove WebSocket server and its topics (foxglove-sdk).

Topics (JSON with a JSON schema, but ``/events``, which uses Foxglove's well-known
``foxglove.Log``), stamped with the sample's time on the recording's axis plus the wall
time the stream started (so Foxglove shows the run at the time it happened):

=================== ==========================================================
``/gauges``         every sample: ``seq``, ``t_ns``, ``x_mm``, ``u_mm``, ``force_n``,
                    ``flags`` (2 kHz)
``/command``        the planned drive position ``x_cmd_mm`` (one per 5 ms)
``/drive``          each drive poll: position, speed, status word, trip, enabled
``/events``         start, stop, e-stop, faults, notes (``foxglove.Log``)
``/model``          the baseline model fed the measured x: ``u_mm``, ``force_n``
``/model/residual`` measured − model: ``u_mm``, ``force_n``
=================== ==========================================================

Nothing is encoded for a topic nobody subscribed to. The server runs in its own threads
(Rust); ``log`` never waits for a client: a client that cannot keep up loses its oldest
messages (the SDK's per-client backlog), never the sender's time.
"""

from __future__ import annotations

import json
import logging
import math
import threading
import time
from collections.abc import Sequence
from typing import Any

import foxglove
import numpy as np
from foxglove.channels import LogChannel
from foxglove.messages import Log, LogLevel, Timestamp
from foxglove.websocket import ChannelView, Client, ServerListener
from numpy.typing import NDArray

from drivers.closing import ClosesOnExit
from labstand.errors import CommandError, ExitCode
from labstand.live.address import ViewerAddress
from labstand.live.model import ModelBlock

log = logging.getLogger(__name__)

__all__ = ["COMMAND_EVERY_NS", "TOPICS", "LiveServer"]

#: /command carries one planned position per this span, ns: the planned motion is smooth.
COMMAND_EVERY_NS = 5_000_000
#: How long a stopping server waits for clients to take what is in flight, s.
LINGER_S = 0.5
#: Messages a client may have outstanding before its oldest are dropped (2 s of all
#: full-rate topics at 2 kHz).
BACKLOG = 16384

_NUMBER = {"type": "number"}
_INT = {"type": "integer"}


def _schema(title: str, **props: dict[str, str]) -> dict[str, Any]:
    return {"title": title, "type": "object", "properties": props}


TOPICS: dict[str, dict[str, Any]] = {
    "/gauges": _schema(
        "labstand.GaugeSample",
        seq=_INT,
        t_ns=_INT,
        x_mm=_NUMBER,
        u_mm=_NUMBER,
        force_n=_NUMBER,
        flags=_INT,
    ),
    "/command": _schema("labstand.Command", t_ns=_INT, x_cmd_mm=_NUMBER),
    "/drive": _schema(
        "labstand.DriveState",
        t_ns=_INT,
        position_mm=_NUMBER,
        speed_mm_s=_NUMBER,
        status_word=_INT,
        trip_code=_INT,
        enabled={"type": "boolean"},
    ),
    "/model": _schema("labstand.ModelSample", t_ns=_INT, u_mm=_NUMBER, force_n=_NUMBER),
    "/model/residual": _schema("labstand.ModelResidual", t_ns=_INT, u_mm=_NUMBER, force_n=_NUMBER),
}
#: foxglove.Log levels by event kind.
_LEVELS = {"estop": "Error", "fault": "Warning", "stop": "Info", "start": "Info", "note": "Info"}


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None  # JSON has no NaN


class _Listener(ServerListener):
    """Notes that a client subscribed to something."""

    def __init__(self) -> None:
        self.subscribed = threading.Event()

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        """A client subscribed to a channel."""
        self.subscribed.set()


class LiveServer(ClosesOnExit):
    """A Foxglove WebSocket server with labstand's topics.

    Raises ``CommandError`` (exit 2) naming the address if it cannot listen there.
    ``epoch_ns`` is added to every recording time (default: the wall time now).
    """

    def __init__(self, address: ViewerAddress, name: str, epoch_ns: int | None = None) -> None:
        self.address = address
        self.epoch_ns = time.time_ns() if epoch_ns is None else epoch_ns
        if logging.getLogger().getEffectiveLevel() > logging.DEBUG:  # without -v
            # a viewer that closes its tab is no error of the run's
            logging.getLogger("foxglove").setLevel(logging.CRITICAL)
        self._context = foxglove.Context()
        self._listener = _Listener()
        try:
            self._server = foxglove.start_server(
                name=name,
                host=address.host,
                port=address.port,
                context=self._context,
                message_backlog_size=BACKLOG,
                server_listener=self._listener,
            )
        except RuntimeError as err:
            reason = str(err).removeprefix("FoxgloveError: ")
            raise CommandError(f"--foxglove {address}: {reason}", ExitCode.USAGE) from None
        self._channels = {
            topic: foxglove.Channel(topic, schema=schema, context=self._context)
            for topic, schema in TOPICS.items()
        }
        self._events = LogChannel("/events", context=self._context)
        self._closed = False
        self._command_slot = -1

    @property
    def port(self) -> int:
        """The port listened on (the one chosen when 0 was asked for)."""
        return self._server.port

    @property
    def url(self) -> str:
        """Where Foxglove connects (Open connection → Foxglove WebSocket)."""
        host = f"[{self.address.host}]" if ":" in self.address.host else self.address.host
        return f"ws://{host}:{self.port}"

    def wait_client(self, timeout_s: float | None = None) -> bool:
        """Wait until a client subscribed to a topic; False on the time-out."""
        return self._listener.subscribed.wait(timeout_s)

    def subscribed(self, topic: str) -> bool:
        """True if a client subscribed to ``topic``."""
        if topic == "/events":
            return self._events.has_sinks()
        return self._channels[topic].has_sinks()

    def _log_rows(self, topic: str, t_ns: Sequence[int], rows: list[dict[str, Any]]) -> None:
        channel = self._channels[topic]
        dumps, epoch = json.dumps, self.epoch_ns
        for t, row in zip(t_ns, rows, strict=True):
            channel.log(dumps(row).encode(), log_time=epoch + t)

    def gauges(self, block: NDArray[np.void]) -> None:
        """Every sample of a gauges block (GAUGES_DTYPE)."""
        if not self.subscribed("/gauges"):
            return
        t_ns = block["t_ns"].tolist()
        columns = [block[n].tolist() for n in ("seq", "x_mm", "u_mm", "force_n", "flags")]
        rows = [
            {"seq": s, "t_ns": t, "x_mm": x, "u_mm": u, "force_n": f, "flags": fl}
            for t, s, x, u, f, fl in zip(t_ns, *columns, strict=True)
        ]
        self._log_rows("/gauges", t_ns, rows)

    def command(self, command: NDArray[np.void]) -> None:
        """The first planned position (COMMAND_DTYPE) in each COMMAND_EVERY_NS span."""
        if not self.subscribed("/command") or not len(command):
            return
        slot = command["t_ns"] // COMMAND_EVERY_NS
        first = np.diff(slot, prepend=self._command_slot) > 0
        self._command_slot = int(slot[-1])
        pick = command[first]
        t_ns = pick["t_ns"].tolist()
        rows = [
            {"t_ns": t, "x_cmd_mm": _finite(x)}
            for t, x in zip(t_ns, pick["x_cmd_mm"].tolist(), strict=True)
        ]
        self._log_rows("/command", t_ns, rows)

    def model(self, t_ns: NDArray[np.int64], block: ModelBlock) -> None:
        """The model and the residual at the samples' times."""
        times = t_ns.tolist()
        for topic, u, f in (
            ("/model", block.u_mm, block.force_n),
            ("/model/residual", block.residual_u_mm, block.residual_force_n),
        ):
            if self.subscribed(topic):
                rows = [
                    {"t_ns": t, "u_mm": a, "force_n": b}
                    for t, a, b in zip(times, u.tolist(), f.tolist(), strict=True)
                ]
                self._log_rows(topic, times, rows)

    def drive(self, row: dict[str, Any]) -> None:
        """One drive poll (a ``RunClock.drive_row``)."""
        if self.subscribed("/drive"):
            out = {k: (bool(v) if k == "enabled" else v) for k, v in row.items()}
            self._log_rows("/drive", [int(row["t_ns"])], [out])

    def event(self, t_ns: int, kind: str, text: str) -> None:
        """An event as a ``foxglove.Log`` message (name: the kind)."""
        stamp = self.epoch_ns + int(t_ns)
        level = getattr(LogLevel, _LEVELS.get(kind, "Info"))
        message = Log(
            timestamp=Timestamp(stamp // 1_000_000_000, stamp % 1_000_000_000),
            level=level,
            message=text or kind,
            name=kind,
        )
        self._events.log(message, log_time=stamp)

    def close(self) -> None:
        """Stop the server (idempotent); clients see the connection close."""
        if not self._closed:
            self._closed = True
            if any(self.subscribed(topic) for topic in (*TOPICS, "/events")):
                time.sleep(LINGER_S)  # the SDK has no flush: let clients take the backlog
            self._server.stop()
