"""The panel's JSON snapshots: the loop's telemetry as the panel shows it, the state (with
servos and the stick figure) and the parameters with their specs (robot.panel.controller
builds them under its lock; FK runs here, on request, not in the loop's thread)."""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Mapping
from typing import Any

from robot.config.model_angles import ModelAngles
from robot.config.params import GROUPS, SPECS, GaitParams
from robot.config.robot import RobotConfig
from robot.loop.telemetry import Telemetry
from robot.panel.figure import views
from robot.panel.labels import LABELS, SIMPLE


class TickRate:
    """The loop's measured rate over its last ``window`` ticks (loop clock) [Hz]."""

    def __init__(self, window: int) -> None:
        self._ticks: deque[tuple[int, float]] = deque(maxlen=window)

    def add(self, tick: int, t: float) -> None:
        if not self._ticks or self._ticks[-1][0] != tick:
            self._ticks.append((tick, t))

    def clear(self) -> None:
        self._ticks.clear()

    def hz(self) -> float:
        ticks = list(self._ticks)
        if len(ticks) < 2 or ticks[-1][1] <= ticks[0][1]:
            return 0.0
        return (ticks[-1][0] - ticks[0][0]) / (ticks[-1][1] - ticks[0][1])


def telemetry_snapshot(tel: Telemetry) -> dict[str, Any]:
    """What the panel keeps of a tick (cheap: copies, no FK)."""
    return {"t": tel.t, "state": tel.state, "tick": tel.tick, "q_cmd": tel.q_cmd,
            "q_present": tel.q_present, "servo": tel.servo,
            "period_error_ms": tel.period_error_ms, "overruns": tel.overruns,
            "amplitude": tel.amplitude, "stop_reason": tel.stop_reason,
            "clamped": list(tel.clamped)}


def show_doing(show: Mapping[str, Any]) -> str:
    """What a playing show is doing, in words: "playing take NAME 3.2 / 30.0 s, next cue
    'lights up' at 5.0 s" (robot.panel.show_clock's progress)."""
    cue = show.get("next_cue")
    return (f"playing take {show['take']} {show['t']:.1f} / {show['duration']:.1f} s"
            + (f", next cue '{cue['name']}' at {cue['t']:.1f} s" if cue else ""))


def state_snapshot(robot: RobotConfig, tel: Mapping[str, Any], sim: Mapping[str, Any], *,
                   running: bool, rate_hz: float, loop_hz: float,
                   show: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """A JSON-ready snapshot: loop state and timing, servos, sim metrics, stick figure;
    while a show plays (``show``: its progress), the state "playing" and ``doing``, what
    it is doing in words; an imported robot's joints in its model's terms (``model``:
    the model's joint names, the commanded and present angles in its convention [rad],
    robot/config/model_angles.py), and each servo's ``model_joint``."""
    names = robot.joint_names
    servos = [{"id": j.servo_id, "joint": j.name, "model_joint": j.model_joint,
               "temperature": s.temperature if s else None,
               "load": s.load if s else None,
               "errors": sorted(s.errors) if s else []}
              for j in robot.joints
              for s in [tel.get("servo", {}).get(j.servo_id)]]
    q_cmd, q_present = tel.get("q_cmd") or [], tel.get("q_present")
    figure = {"cmd": views(robot, q_cmd) if len(q_cmd) == len(names) else None,
              "present": views(robot, q_present)
              if q_present and len(q_present) == len(names) else None}
    model = None
    if robot.body is not None:
        angles = ModelAngles.of(robot)
        model = {"joints": list(angles.names),
                 "q_cmd": angles.values(q_cmd).tolist() if len(q_cmd) == len(names) else None,
                 "q_present": angles.values(q_present).tolist()
                 if q_present and len(q_present) == len(names) else None}
    state = tel.get("state", "idle")
    playing = bool(running and show and show.get("playing") and state == "walking")
    return {
        "running": running, "state": "playing" if playing else state,
        "doing": show_doing(show) if playing and show else None, "t": tel.get("t", 0.0),
        "tick": tel.get("tick", 0), "rate_hz": rate_hz,
        "loop_hz": loop_hz, "period_error_ms": tel.get("period_error_ms", 0.0),
        "overruns": tel.get("overruns", 0), "amplitude": tel.get("amplitude", 0.0),
        "stop_reason": tel.get("stop_reason"), "clamped": list(tel.get("clamped", [])),
        "joints": list(names),
        "q_cmd": q_cmd, "q_present": q_present, "servos": servos, "sim": sim or None,
        "figure": figure, "model": model, "wall_time": time.time()}


def describe_params(params: GaitParams, preset: str | None) -> dict[str, Any]:
    """Parameters with their specs, grouped as the paper groups its sliders."""
    p = params.as_dict()
    return {
        "params": p, "preset": preset,
        "groups": [{"name": g, "params": [
            {"name": n, "value": p[n], "lo": s.lo, "hi": s.hi, "unit": s.unit,
             "default": s.default, "doc": s.doc, "paper": s.paper,
             "label": LABELS.get(n, n), "simple": n in SIMPLE}
            for n, s in SPECS.items() if s.group == g]} for g in GROUPS],
    }
