"""Simulation metrics for the panel: fell or not, torso height, tilt, distance."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from robot.loop.streamer import Telemetry


def sim_monitor_factory(bus: Any) -> Callable[[], Callable[[Telemetry], dict[str, Any]]]:
    """Per-run WalkMonitor on a MujocoBus: fell or not, torso height, tilt, distance."""
    from sim.mujoco.metrics import WalkMonitor

    def factory() -> Callable[[Telemetry], dict[str, Any]]:
        monitor = WalkMonitor(standing_height=bus.standing_height)
        last = [-1]

        def watch(tel: Telemetry) -> dict[str, Any]:
            if tel.tick != last[0]:
                last[0] = tel.tick
                pos, quat = bus.base_pose()
                monitor.update(tel.t, pos, quat, bus.upright_angle())
            s = monitor.summary(1.0)
            return {"fell": s["fell"], "fell_at_s": s["fell_at_s"],
                    "distance_m": s["distance_m"], "heading_deg": s["heading_change_deg"],
                    "torso_height_m": float(bus.base_pose()[0][2]),
                    "tilt_deg": float(bus.upright_angle() * 57.29577951308232)}
        return watch
    return factory
