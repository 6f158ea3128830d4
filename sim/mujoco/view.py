"""Helpers of the MuJoCo bus that touch the wall clock or a display: the sim-time clock,
the passive viewer (and its display check), realtime pacing, offscreen rendering."""

from __future__ import annotations

import logging
import os
import time
from typing import Any, Protocol

import mujoco
import numpy as np
import numpy.typing as npt

from robot.errors import BusError

log = logging.getLogger(__name__)

VIEW_SYNC_S = 1 / 60  # viewer refresh period [wall s]
REANCHOR_LAG_S = 0.25  # realtime: behind the wall clock by more than this → re-anchor [s]


class Stepped(Protocol):
    """What the clock needs of the MuJoCo bus: its data (``time`` [s]) and ``advance``."""

    @property
    def data(self) -> mujoco.MjData: ...

    def advance(self, deadline: float) -> None: ...


class SimClock:
    """``robot.loop.clock.Clock`` on simulation time: ``sleep_until`` steps the physics."""

    def __init__(self, bus: Stepped) -> None:
        self._bus = bus

    def now(self) -> float:
        """Simulation time [s]."""
        return float(self._bus.data.time)

    def sleep_until(self, deadline: float) -> None:
        """Step the physics until ``now() == deadline`` (no-op if already past)."""
        self._bus.advance(deadline)


def check_display() -> None:
    """BusError unless a window can open (MuJoCo's viewer exits the process otherwise)."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise BusError("--view needs a display; run without --view or use `biped render`")
    import glfw

    reporting, glfw.ERROR_REPORTING = glfw.ERROR_REPORTING, "ignore"
    try:
        ok = glfw.init()
    finally:
        glfw.ERROR_REPORTING = reporting
    if not ok:
        display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
        raise BusError(f"--view: cannot open display {display!r}; run without --view or "
                       f"use `biped render`")


def launch_viewer(model: mujoco.MjModel, data: mujoco.MjData) -> Any:
    import mujoco.viewer as mujoco_viewer

    return mujoco_viewer.launch_passive(model, data)


class WallPacer:
    """Realtime pacing and viewer refresh on the wall clock."""

    def __init__(self) -> None:
        self.wall0 = 0.0  # wall time [s] at sim time 0
        self._last_sync = -float("inf")

    def anchor(self, sim_time: float) -> None:
        self.wall0 = time.monotonic() - sim_time

    def wait(self, deadline: float) -> None:
        """Sleep until the wall clock reaches sim time ``deadline`` [s]; re-anchor instead
        when more than REANCHOR_LAG_S behind."""
        wall_deadline = self.wall0 + deadline
        lag = time.monotonic() - wall_deadline
        if lag > REANCHOR_LAG_S:
            log.debug("sim bus: %.3f s behind real time; re-anchoring", lag)
            self.wall0 += lag
            return
        while (remaining := wall_deadline - time.monotonic()) > 0:
            time.sleep(remaining)

    def sync_viewer(self, viewer: Any) -> None:
        now = time.monotonic()
        if now - self._last_sync < VIEW_SYNC_S:
            return
        self._last_sync = now
        if viewer.is_running():
            viewer.sync()


class OffscreenRenderer:
    """One ``mujoco.Renderer``, rebuilt when the frame size changes."""

    def __init__(self) -> None:
        self._r: mujoco.Renderer | None = None

    def render(self, model: mujoco.MjModel, data: mujoco.MjData, width: int, height: int,
               camera: str) -> npt.NDArray[np.uint8]:
        r = self._r
        if r is None or (r.width, r.height) != (width, height):
            self.close()
            try:
                r = mujoco.Renderer(model, height=height, width=width)
            except ValueError as e:
                raise BusError(f"sim bus: render {width}x{height}: {e}") from e
            self._r = r
        try:
            r.update_scene(data, camera=camera)
        except ValueError as e:
            raise BusError(f"sim bus: render: no camera {camera!r} ({e})") from e
        return r.render()

    def close(self) -> None:
        if self._r is not None:
            self._r.close()
            self._r = None
