"""SIGINT/SIGTERM for commands that stream: robot.run.signals (where the Run owns them)."""

from __future__ import annotations

from robot.run.signals import SIGNALS, SignalLatch, Stoppable, stop_on_signals

__all__ = ["SIGNALS", "SignalLatch", "Stoppable", "stop_on_signals"]
