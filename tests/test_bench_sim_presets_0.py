"""`biped bench --only sim`'s preset walks, part 1 of 3 (tests/bench_presets.py): every
bundled gait preset walked 5 s by the bench on every robot of ``robot_names()[0::3]``."""

from __future__ import annotations

import pytest
from bench_presets import walk_part


def test_the_bench_walks_every_preset_on_its_robots(monkeypatch: pytest.MonkeyPatch) -> None:
    walk_part(monkeypatch, 0)
