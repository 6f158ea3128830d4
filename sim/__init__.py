"""MuJoCo side of biped: MJCF generation, the simulated bus, and the pty servo emulator.

Headless machines (no DISPLAY / WAYLAND_DISPLAY) render offscreen with EGL; MuJoCo reads
MUJOCO_GL when it is first imported, so the default is set here, before any import of it.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robot.bus.base import Bus
    from robot.config.robot import RobotConfig

if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("MUJOCO_GL", "egl")


def open_bus(robot: RobotConfig, *, port: str | None = None, baud: int | None = None,
             **options: Any) -> Bus:
    """The ``sim`` bus plugin (entry point group ``biped.buses``, see pyproject.toml): a
    MuJoCo bus for ``robot``; ``port`` and ``baud`` do not apply to it and are ignored."""
    from sim.mujoco.bus import MujocoBus

    return MujocoBus(robot, **options)
