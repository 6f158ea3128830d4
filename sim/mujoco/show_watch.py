"""What the physics check of a show (`biped play` on the sim bus) records every control
tick: the support margin, the torso's tilt, every servo's torque, and the temperatures the
bus reports.

Support margin [m]: the signed distance from the robot's centre of mass, projected on the
floor, to the edge of the support polygon (the convex hull of the soles touching the
ground: ``BodyObservation.sole_corners``); positive inside, negative outside, NaN with no
foot down. Torque: the actuators' force [N m] (``data.actuator_force``, as
sim/mujoco/effort.py reads it); temperature [°C]: what ``read_state`` reported on the
ticks that read the servos back (the telemetry: whatever servo model the bus runs).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from robot.loop.telemetry import Telemetry
from sim.mujoco.bus import MujocoBus

Array = npt.NDArray[np.float64]


def hull(points: Array) -> Array:
    """Convex hull (k, 2) of 2-D points, counter-clockwise (Andrew's monotone chain)."""
    pts = sorted({(float(x), float(y)) for x, y in points})
    if len(pts) < 3:
        return np.array(pts)

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out
    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def margin(point: Array, polygon: Array) -> float:
    """Signed distance [m] of ``point`` (2,) to the edge of a counter-clockwise convex
    ``polygon`` (k, 2): positive inside."""
    if len(polygon) < 3:
        return math.nan
    a, b = polygon, np.roll(polygon, -1, axis=0)
    edge = b - a
    length = np.linalg.norm(edge, axis=1)
    inside = (edge[:, 0] * (point[1] - a[:, 1]) - edge[:, 1] * (point[0] - a[:, 0])) / length
    if np.all(inside >= 0):
        return float(inside.min())
    s = np.clip(np.sum((point - a) * edge, axis=1) / length**2, 0.0, 1.0)
    return -float(np.min(np.linalg.norm(a + s[:, None] * edge - point, axis=1)))


class ShowWatch:
    """A tick observer on the sim ``bus`` (opened by the run before the first tick); lists
    by tick after the run; ``start``: loop time [s] of the source's first tick (the show's
    start, after the ramp in)."""

    def __init__(self, bus: MujocoBus) -> None:
        self.bus = bus
        self.joints = bus.robot.joint_names
        self._ids = [j.servo_id for j in bus.robot.joints]
        self._act: npt.NDArray[np.intp] | None = None
        self.start: float | None = None
        self.t: list[float] = []
        self.margin: list[float] = []
        self.tilt: list[float] = []
        self.torque: list[Array] = []
        self.temp_t: list[float] = []
        self.temperature: list[list[float]] = []

    def __call__(self, tel: Telemetry) -> None:
        bus = self.bus
        if self._act is None:
            self._act = np.array([bus.model.actuator(n).id for n in self.joints])
        if self.start is None and tel.state == "walking":
            self.start = tel.t
        corners = bus.sole_corners()
        com = bus.data.subtree_com[1][:2]
        m = margin(com, hull(np.vstack(corners)[:, :2])) if corners else math.nan
        self.t.append(tel.t)
        self.margin.append(m)
        self.tilt.append(bus.upright_angle())
        self.torque.append(np.abs(bus.data.actuator_force[self._act]))
        if tel.fresh and tel.servo:
            temps = [tel.servo[i].temperature if i in tel.servo else math.nan
                     for i in self._ids]
            self.temp_t.append(tel.t)
            self.temperature.append([math.nan if v is None else float(v) for v in temps])
