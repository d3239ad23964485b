"""Fixtures of the live-view tests: an independent Foxglove client, and labstand's URL.

The client is the ``@foxglove/ws-protocol`` package's ``FoxgloveClient`` in Node
(tests/live/node/client.js; ``make node-tools`` installs it), a WebSocket client this
project did not write.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import pytest

from tests.recordings.conftest import meta
from tests.run.conftest import labstand, no_leaks, run_process

__all__ = ["labstand", "meta", "no_leaks", "run_process"]

NODE_DIR = Path(__file__).parent / "node"


class NodeClient:
    """``node client.js URL [--stall S]`` as a child process."""

    def __init__(self, url: str, stall_s: float = 0.0) -> None:
        if shutil.which("node") is None:
            pytest.fail("node is not installed (make node-tools installs it)")
        if not (NODE_DIR / "node_modules" / "@foxglove" / "ws-protocol").is_dir():
            pytest.fail("@foxglove/ws-protocol is not installed (make node-tools)")
        cmd = ["node", str(NODE_DIR / "client.js"), url]
        if stall_s:
            cmd += ["--stall", str(stall_s)]
        self.process = subprocess.Popen(
            cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )

    def wait_line(self) -> dict[str, Any]:
        """The next JSON line it prints (the stalled client's ``{"stalled": true}``)."""
        assert self.process.stdout is not None
        line = self.process.stdout.readline()
        if not line:
            pytest.fail(f"the Node client printed nothing: {self.stderr()}")
        found: dict[str, Any] = json.loads(line)
        return found

    def finish(self, timeout_s: float = 60.0) -> dict[str, Any]:
        """Its report, once the server closed the connection."""
        out, err = self.process.communicate(timeout=timeout_s)
        assert self.process.returncode == 0, err
        found: dict[str, Any] = json.loads(out.splitlines()[-1])
        return found

    def stderr(self) -> str:
        self.kill()
        assert self.process.stderr is not None
        return self.process.stderr.read()

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait(10)


@pytest.fixture
def node_client() -> Iterator[type[NodeClient]]:
    """Start Node clients; each is killed and reaped at the end of the test."""
    started: list[NodeClient] = []

    class Tracked(NodeClient):
        def __init__(self, url: str, stall_s: float = 0.0) -> None:
            super().__init__(url, stall_s)
            started.append(self)

    yield Tracked
    for client in started:
        client.kill()
        for stream in (client.process.stdout, client.process.stderr):
            if stream is not None:
                stream.close()


def read_url(stdout: IO[str], lines: list[str], timeout_lines: int = 50) -> str:
    """Read labstand's stdout up to its 'live view: ws://...' line; the URL."""
    for _ in range(timeout_lines):
        line = stdout.readline()
        if not line:
            break
        lines.append(line)
        found = re.search(r"live view: (ws://\S+)", line)
        if found:
            return found[1]
    pytest.fail(f"no live-view line: {''.join(lines)}")
