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


#: The longest test files, longest first (a quiet `make test` with --durations=0, 1b99434:
#: 217, 164, 99, 99, 76, 72, 52, 44, 42 s). pytest-xdist's loadfile split hands out whole
#: files and, by default, the files with the most tests first, which left the one-test
#: files that run for 40-50 s (the sim bench, the tuner) to the end, one worker busy and
#: the others idle. `make unit` turns that order off (--no-loadscope-reorder); this one
#: hands out these files first, then the rest by their number of tests, as before.
#: The longest files were then split so that no file bounds the suite alone (one file
#: runs on one worker): the fault matrix (198 s wall, its walks run in real time on the
#: pty) in three, the command end paths (104 s) in two, the sim bench's 72 preset walks
#: in three, the tuner's study tests out of test_tune.py.
LONGEST_FIRST = ("test_fault_matrix.py", "test_command_ends.py", "test_command_ends_more.py",
                 "test_fault_matrix_ends.py", "test_fault_matrix_signals.py",
                 "test_setup_motors.py", "test_zoo_wire.py", "test_panel_end_paths.py",
                 "test_walk_sim.py", "test_bench_sim.py", "test_tune_detuned.py",
                 "test_tune_study.py", "test_bench_sim_presets_0.py",
                 "test_bench_sim_presets_1.py", "test_tune.py")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    count: dict[str, int] = {}
    for item in items:
        count[item.path.name] = count.get(item.path.name, 0) + 1
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: (rank.get(item.path.name, len(rank)),
                                 -count[item.path.name], item.path.name))
