"""docs/effects.md's parameter tables say what the CLI enforces: every parameter row's
default and admissible range are the registry's (the CLI checks ``--effect`` by them)."""

from __future__ import annotations

import re
from pathlib import Path

from sim.effects import EFFECTS

DOC = Path(__file__).resolve().parents[2] / "docs" / "effects.md"
ROW = re.compile(
    r"^\| `(\w+)` \| [^|]* \| ([^|]+) \| [^|]+ \| (\S+) – (\S+) \| [^|]+ \|$", re.MULTILINE
)


def test_the_documented_ranges_are_the_enforced_ones() -> None:
    text = DOC.read_text(encoding="utf-8")
    checked = 0
    for section in re.split(r"^### ", text, flags=re.MULTILINE)[1:]:
        effect = re.match(r"`(\w+)`", section)
        if effect is None or effect[1] not in EFFECTS:
            continue
        params = {p.name: p for p in EFFECTS[effect[1]].params}
        for name, default, low, high in ROW.findall(section.split("\n## ")[0]):
            p = params[name]
            where = f"{effect[1]}.{name}"
            assert (float(low), float(high)) == (p.minimum, p.maximum), where
            assert float(default) == p.default, where
            checked += 1
    assert checked >= sum(len(i.params) for i in EFFECTS.values()) // 2  # the tables were read
