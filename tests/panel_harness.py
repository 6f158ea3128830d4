"""Shared pieces of the panel's browser tests: Debian's headless Chromium through
Playwright (one browser per test module), the walking panel on the MuJoCo bus behind a
served page, and a polling wait.

Use from a test module with ``pytest_plugins = ("panel_harness",)`` (the ``browser``
fixture) and import the helpers.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
import waiting
from playwright.sync_api import Browser, sync_playwright

from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.panel.controller import BusSpec, LoopOptions, PanelController, make_controller
from robot.panel.server import build_server, serve_in_thread
from robot.panel.studio import Studio

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def wait_for(pred: Callable[[], bool], timeout: float = 10.0) -> bool:
    """``pred`` held within ``timeout`` [s] (polled; see waiting.wait_for)."""
    return waiting.wait_for(pred, timeout_s=timeout)


@contextmanager
def served_panel(*, studio_dir: Path | None = None) -> Iterator[tuple[PanelController, str]]:
    """The default robot's panel (walk preset, 100 Hz, real time on the MuJoCo bus) served
    on a free port: (controller, base URL); emergency stop and shutdown at the end.
    studio_dir: also serve the studio (takes and keyframes under it)."""
    robot = load_robot(DEFAULT_ROBOT)
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5),
                                 preset="walk")
    studio = None if studio_dir is None else Studio(
        controller, takes_dir=studio_dir / "takes", keys_dir=studio_dir / "keys")
    server = build_server(controller, port=0, studio=studio)
    _, base = serve_in_thread(server)
    try:
        yield controller, base
    finally:
        server.shutdown()
        server.server_close()
        controller.emergency_stop()
        controller.shutdown()


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()
