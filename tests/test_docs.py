"""docs/gait.md is up to date with the code: the parameter table is SPECS, the channel
table lists every channel in equations.md order, every deviation and preset is there."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from test_gait import EQUATIONS

from robot.config import docs_gen
from robot.config.bundled import gait_names
from robot.config.params import ALIASES, SPECS

DOC = docs_gen.DOC
TEXT = DOC.read_text()


def section(begin: str, end: str) -> str:
    return TEXT.split(begin, 1)[1].split(end, 1)[0]


def test_parameter_table_is_generated_from_specs() -> None:
    assert docs_gen.render(TEXT) == TEXT, "run: python -m robot.config.docs_gen"


def test_parameter_table_has_every_parameter_once() -> None:
    table = section(docs_gen.BEGIN, docs_gen.END)
    names = re.findall(r"^\| `(\w+)`", table, flags=re.M)
    assert names == list(SPECS)
    for alias in ALIASES:
        assert f"`{alias}`" in table
    fps = next(line for line in table.splitlines() if line.startswith("| `fps`"))
    assert "[1, 240]" in fps and fps.endswith("| 24 |")
    sway_phase = next(line for line in table.splitlines() if line.startswith("| `sway_phase`"))
    assert "[-π, π]" in sway_phase


def test_render_replaces_a_stale_table(tmp_path: Path) -> None:
    stale = tmp_path / "gait.md"
    stale.write_text(f"intro\n{docs_gen.BEGIN}\n| old |\n{docs_gen.END}\noutro\n")
    assert docs_gen.main([str(stale)]) == 0
    text = stale.read_text()
    assert "| old |" not in text and "`ramp_cycles`" in text
    assert text.startswith("intro\n") and text.endswith("\noutro\n")
    with pytest.raises(ValueError, match="markers"):
        docs_gen.render("no markers here")


def test_channel_table_lists_every_channel_in_equation_order() -> None:
    rows = re.findall(r"^\| (\d+) \| `(\w+)` \| (.+) \|$",
                      section("<!-- channels:begin -->", "<!-- channels:end -->"), flags=re.M)
    assert [(eq, ch) for eq, ch, _ in rows] == [(eq, ch) for eq, ch, _ in EQUATIONS]
    assert all(effect.strip() for _, _, effect in rows)


@pytest.mark.parametrize("topic", [
    "Left leg in anti-phase", "`delta_f` means the same for both feet", "Ground clamp",
    "Lateral sway", "Steering", "Envelope", "Amplitude scaling by leg length",
    "Integrated phase", "Arm swing sign", "No spine joint",
])
def test_every_deviation_is_documented(topic: str) -> None:
    assert f"**{topic}" in TEXT


def test_every_preset_is_documented() -> None:
    presets = section("## Presets", "## Known limits")
    for name in gait_names():
        assert f"| `{name}` |" in presets, name
