"""The progress bar on a terminal (a real pty), and one line per job elsewhere."""

from __future__ import annotations

import io
import os
import re
import select

from labstand.distributed import Progress


def test_on_a_terminal_a_bar_with_done_total_and_eta() -> None:
    master, slave = os.openpty()
    try:
        with open(slave, "w", closefd=False) as tty:
            progress = Progress("labstand diagnose", 4, stream=tty)
            progress.say("local cluster: 2 worker process(es)")
            progress.advance("light: none (20 s)")
            progress.close()
        chunks = []
        while select.select([master], [], [], 0.2)[0]:
            chunks.append(os.read(master, 65536))
        text = b"".join(chunks).decode()
    finally:
        os.close(master)
        os.close(slave)
    assert "labstand diagnose: local cluster: 2 worker process(es)" in text
    assert "labstand diagnose: light: none (20 s)" in text
    plain = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text)  # the drawn text without colours
    assert re.search(r"labstand diagnose ━+ 0/4 ETA", plain)  # rich's bar, as the run's panel
    assert re.search(r"labstand diagnose ━{10}╺━+ 1/4 ETA", plain)  # a quarter filled
    assert text.endswith("\x1b[2K")  # closed: the bar's line is cleared (the jobs' stay)
    assert "\x1b[?25h" in text  # and the cursor shown again


def test_elsewhere_one_line_per_job_and_quiet_for_json() -> None:
    log = io.StringIO()
    progress = Progress("labstand table1", 2, stream=log)
    progress.advance("a.mcap: ok")
    progress.advance("b.mcap: ok")
    lines = log.getvalue().splitlines()
    assert lines[0].startswith("labstand table1: [1/2, ETA ") and lines[0].endswith("] a.mcap: ok")
    assert lines[1] == "labstand table1: [2/2] b.mcap: ok"
    quiet = io.StringIO()
    progress = Progress("labstand table1", 1, quiet=True, stream=quiet)
    progress.say("where")
    progress.advance("a.mcap: ok")
    progress.say("important", always=True)
    assert quiet.getvalue() == "labstand table1: important\n"
