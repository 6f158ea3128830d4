"""Shared fixtures: the bundled robot configs and gait presets (keep this file small)."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless: before anything imports mujoco

import pytest
from hypothesis import settings

from robot.config.bundled import GAITS_DIR, ROBOTS_DIR
from robot.config.gait_file import Gait, load_gait
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot

# `make test` draws the same hypothesis examples on every machine, so a pass is reproducible
# and CI never fails on a draw nobody has seen; `make fuzz` draws fresh ones (and more) to
# look for new failures, which then become explicit examples.
settings.register_profile("repeatable", derandomize=True, print_blob=True)
settings.register_profile("fuzz", max_examples=2000, print_blob=True)
settings.load_profile(os.environ.get("BIPED_HYPOTHESIS", "repeatable"))

ROBOT_FILES = sorted(p.name for p in ROBOTS_DIR.glob("*.toml"))
GAIT_FILES = sorted(p.stem for p in GAITS_DIR.glob("*.toml"))


@pytest.fixture(params=ROBOT_FILES)
def any_robot(request: pytest.FixtureRequest) -> RobotConfig:
    """Each bundled robot config in turn."""
    return load_robot(ROBOTS_DIR / request.param)


@pytest.fixture(params=[f for f in ROBOT_FILES if load_robot(ROBOTS_DIR / f).has_arms])
def armed_robot(request: pytest.FixtureRequest) -> RobotConfig:
    """Each bundled robot config that has arms."""
    return load_robot(ROBOTS_DIR / request.param)


@pytest.fixture(params=GAIT_FILES)
def any_gait(request: pytest.FixtureRequest) -> Gait:
    """Each bundled gait preset in turn."""
    return load_gait(request.param)
