"""One root exception for the project; subclasses say which layer failed.

Messages say what was wrong, where (file, field, servo id) and how to fix it.
"""

from __future__ import annotations


class BipedError(Exception):
    """Root of every error this package raises on purpose."""


class ConfigError(BipedError):
    """A robot or gait file, CLI argument or live parameter is invalid."""


class BusError(BipedError):
    """A servo bus operation failed: names the servo id, its joint, the SDK's message and a fix."""


class SafetyStop(BipedError):
    """The watchdog stopped the robot; the message gives the reason."""


class StartRefused(SafetyStop):
    """A run refused to start before torque-on (nothing moved, torque untouched)."""


class BusDead(SafetyStop):
    """The watchdog gave up on the bus (a streak of failed transactions): nothing can be
    ramped, and every further transaction would only cost its timeout."""
