"""The Foxglove layouts in docs/foxglove/: as generated, and naming only what exists."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from labstand.live.layouts import LAYOUTS, render
from labstand.live.server import TOPICS
from recordings.proto import _MESSAGES

DOCS = Path(__file__).parents[2] / "docs" / "foxglove"


def _paths(node: Any) -> list[str]:
    """Every message path a layout names (series values, x paths, topics)."""
    found: list[str] = []
    if isinstance(node, dict):
        for key, value in node.items():
            if key in {"value", "xValuePath", "topicPath", "topicToRender"} and isinstance(
                value, str
            ):
                found.append(value)
            else:
                found += _paths(value)
    elif isinstance(node, list):
        for item in node:
            found += _paths(item)
    return found


def test_shipped_layouts_are_the_generated_ones() -> None:
    for name, make in LAYOUTS.items():
        assert (DOCS / name).read_text(encoding="utf-8") == render(make()), (
            f"docs/foxglove/{name} is stale: python -m labstand.live.layouts docs/foxglove"
        )


def test_live_layout_names_live_topics_and_their_fields() -> None:
    layout = json.loads((DOCS / "live-layout.json").read_text(encoding="utf-8"))
    paths = _paths(layout)
    assert {"/gauges.u_mm", "/model.u_mm", "/model/residual.force_n", "/events"} <= set(paths)
    for path in paths:
        topic, _, field = path.partition(".")
        if topic == "/events":
            continue  # foxglove.Log, the Log panel's own
        assert topic in TOPICS, path
        if field:
            assert field in TOPICS[topic]["properties"], path


def test_recording_layout_names_fields_of_the_file() -> None:
    layout = json.loads((DOCS / "recording-layout.json").read_text(encoding="utf-8"))
    messages = {"/gauges": "GaugeBatch", "/command": "CommandBatch"}
    plotted = 0
    for path in _paths(layout):
        found = re.fullmatch(r"(/\w+)\.(\w+)\[:\]", path)
        if found is None:
            assert path in {"/events", "/drive"}, path
            continue
        fields = {name for name, _, repeated in _MESSAGES[messages[found[1]]] if repeated}
        assert found[2] in fields, path
        plotted += 1
    assert plotted == 8  # 4 series, each with its t_s
