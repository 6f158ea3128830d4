"""The sim bench's preset walks (robot.bench.sim.run_presets) split over three test files,
so that pytest's file-per-worker split walks them side by side (one file walked all 72,
the suite's longest test: 30 CPU-s).

Each file runs the bench's own ``run_presets`` on a third of the bundled robots: the name
the bench reads its robots from is pointed at the part (every gait preset still walked on
each), and the file checks the bench's output for exactly those robots. The parts are
``robot_names()[i::3]``, so every bundled robot, a new one too, is in exactly one."""

from __future__ import annotations

from typing import Any

import pytest

import robot.bench.sim
from robot.bench.sim import run_presets
from robot.config.bundled import gait_names, robot_names

PARTS = 3


def part(i: int) -> list[str]:
    """The bundled robots the i-th file walks (i in 0..PARTS-1)."""
    return robot_names()[i::PARTS]


def only_robots(monkeypatch: pytest.MonkeyPatch, robots: list[str]) -> None:
    """The bench walks ``robots`` alone (the name it reads must exist: raising=True)."""
    monkeypatch.setattr(robot.bench.sim, "robot_names", lambda: list(robots))


def assert_presets_walked(presets: dict[str, Any], robots: list[str]) -> None:
    """The bench's preset report for ``robots``: 5 s each (quick), every preset on every
    robot, and no preset meant for a robot fell (the 60 s figures: docs/servos.md)."""
    assert robots
    assert presets["seconds"] == 5.0
    assert {k for k in presets if " " in k} == {f"{r} {g}" for r in robots
                                                for g in gait_names()}
    assert presets["all_walked"] is True, presets


def walk_part(monkeypatch: pytest.MonkeyPatch, i: int) -> None:
    robots = part(i)
    only_robots(monkeypatch, robots)
    assert_presets_walked(run_presets(quick=True), robots)
