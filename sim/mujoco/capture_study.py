"""Which pushes a walking robot can survive without a step it cannot take: the capture
point (linear inverted pendulum) right after each push of the robustness suite, against
the feet on the ground at that moment.

Run: ``python -m sim.mujoco.capture_study [--robot NAME] [--impulse 1.0]``. For every push of the
suite (4 directions x 4 phases of the step) it walks the open-loop gait in MuJoCo up to the
push, applies it, and 20 ms later (the push's end) reads the whole robot's centre of mass
c, its velocity v and the feet in contact. The capture point is xi = c + v / omega0,
omega0 = sqrt(g / c_z): where the centre of pressure must be for the robot to come to rest
over it. If xi lies outside the support polygon (the convex hull of the soles on the
ground) the robot must step; if the only foot in the air is on the other side of the
stance foot from xi, no step of the gait's legs can reach it (a crossover step would be
needed). This is physics of the model, independent of the balance controller.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import NamedTuple

import mujoco
import numpy as np

from robot.balance.capturability import hull
from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_AT_S, PUSH_PHASES
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer, Telemetry
from sim.mujoco.bus import MujocoBus
from sim.mujoco.geoms import foot_geoms, sole_points
from sim.mujoco.world import PUSH_WINDOW_S

GRAVITY = 9.81  # [m/s^2]
DIRECTIONS = {"forward": (1.0, 0.0), "backward": (-1.0, 0.0), "left": (0.0, 1.0),
              "right": (0.0, -1.0)}


class Capture(NamedTuple):
    """One push: direction, phase [cycle], feet on the ground (right, left), how far the
    capture point is outside the support polygon [m] (<= 0: inside), and whether the foot
    in the air is on the capture point's side (a step can reach it)."""

    direction: str
    phase: float
    contacts: tuple[bool, bool]
    outside_m: float
    steppable: bool


def outside_distance(point: np.ndarray, hull: np.ndarray) -> float:
    """Signed distance of ``point`` from the convex polygon ``hull`` [m]: > 0 outside (to
    the nearest edge), <= 0 inside (minus the distance to the nearest edge)."""
    n = len(hull)
    inside = True
    best = math.inf
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        edge = b - a
        rel = point - a
        if edge[0] * rel[1] - edge[1] * rel[0] < 0:
            inside = False
        t = min(1.0, max(0.0, float(np.dot(rel, edge) / np.dot(edge, edge))))
        best = min(best, float(np.linalg.norm(point - (a + t * edge))))
    return -best if inside else best


def capture_after_push(robot_name: str, direction: str, phase: float,
                       impulse: float) -> Capture:
    robot = load_robot(robot_name)
    params = load_gait("walk").params
    bus = MujocoBus(robot)
    bus.open()
    m, d = bus.model, bus.data
    engine = GaitEngine(robot, params)
    at = PUSH_AT_S + phase * params.cycle_s
    ux, uy = DIRECTIONS[direction]
    state: dict[str, float] = {}
    streamer: Streamer

    def observe(tel: Telemetry) -> None:
        if tel.state != "walking":
            return
        t0 = state.setdefault("t0", tel.t)
        if "pushed" not in state and tel.t - t0 >= at:
            bus.push(ux * impulse, uy * impulse)
            state["pushed"] = tel.t
        elif "pushed" in state and tel.t - state["pushed"] >= PUSH_WINDOW_S:
            streamer.emergency_stop("measured")
    streamer = Streamer(ServoMap(robot), bus, engine, observer=observe)
    try:
        streamer.run(seconds=at + 1.0)
        mujoco.mj_subtreeVel(m, d)
        root = m.body("torso").id
        com = np.array(d.subtree_com[root])
        vel = np.array(d.subtree_linvel[root])
        feet = foot_geoms(m)
        touching = bus.contacts_feet()
        corners = [np.concatenate([sole_points(m, d, g)[:, :2] for g in foot])
                   for foot, on in zip(feet, touching, strict=True) if on]
    finally:
        bus.close()
    w0 = math.sqrt(GRAVITY / com[2])
    xi = com[:2] + vel[:2] / w0
    if not corners:
        return Capture(direction, phase, touching, math.inf, False)
    out = outside_distance(xi, hull(np.vstack(corners)))
    # A foot in the air can reach xi if it is on xi's side of the standing foot.
    steppable = False
    for g, on in zip(feet, touching, strict=True):
        if not on:
            fx, fy = d.geom_xpos[g][:2]
            stand = [d.geom_xpos[h][:2] for h, o in zip(feet, touching, strict=True) if o]
            sy = float(np.mean([s[1] for s in stand]))
            side_xi, side_foot = xi[1] - sy, fy - sy
            steppable = steppable or side_xi * side_foot >= 0 or abs(xi[1] - sy) < 0.02
    if all(touching):
        steppable = True          # double support: either foot can step
    return Capture(direction, phase, touching, out, steppable)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sim.mujoco.capture_study", description=__doc__)
    ap.add_argument("--robot", default="biped18-dynamixel")
    ap.add_argument("--impulse", type=float, default=1.0, help="push [N*s]")
    args = ap.parse_args(argv)
    print(f"{'push':<10}{'phase':>6}  {'feet down':<10}{'xi outside':>11}  step reaches")
    for direction in DIRECTIONS:
        for phase in PUSH_PHASES:
            c = capture_after_push(args.robot, direction, phase, args.impulse)
            feet = {(True, True): "both", (True, False): "right", (False, True): "left",
                    (False, False): "none"}[c.contacts]
            print(f"{direction:<10}{phase:>6g}  {feet:<10}{100 * c.outside_m:>9.1f} cm  "
                  f"{'yes' if c.steppable else 'NO (other side)'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
