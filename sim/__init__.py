"""MuJoCo side of biped: MJCF generation, the simulated bus, and the pty servo emulator.

Headless machines (no DISPLAY / WAYLAND_DISPLAY) render offscreen with EGL; MuJoCo reads
MUJOCO_GL when it is first imported, so the default is set here, before any import of it.
"""

import os

if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("MUJOCO_GL", "egl")
