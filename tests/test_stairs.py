"""Stairs in the sim (`biped walk --stairs H,N`, sim.mujoco.world_stairs): the ground's
height ahead of the robot, found by ray casts on the compiled scene, against a hand
computation from H, N, the tread depth, the landing and the first riser's place; the world's
checks; the condition's `biped walk` options."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robot.config.robot_file import load_robot  # noqa: E402
from robot.errors import ConfigError  # noqa: E402
from robot.tuning.conditions import Condition  # noqa: E402
from sim.mujoco.mjcf import build_mjcf  # noqa: E402
from sim.mujoco.world import World  # noqa: E402
from sim.mujoco.world_stairs import (  # noqa: E402
    STAIR_LANDING_M,
    STAIRS_HALF_WIDTH_M,
    STAIRS_X0_M,
    stairs_end_m,
)

ROBOT = load_robot("biped18-dynamixel")
EDGE = 1e-3  # sample this far [m] either side of a riser


def ground(model: mujoco.MjModel, x: float, y: float) -> float:
    """Height [m] of whatever static geom (floor or step) is under (x, y): a ray straight
    down from 1 m that sees only the world body's geoms (group filter: none; the robot's
    bodies are excluded by casting away from them, at |y| well outside its feet)."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geomid = np.zeros(1, np.int32)
    dist = mujoco.mj_ray(model, data, np.array([x, y, 1.0]), np.array([0.0, 0.0, -1.0]),
                         None, 1, -1, geomid)
    assert geomid[0] >= 0 and model.geom_bodyid[geomid[0]] == 0
    return 1.0 - dist


def hand_profile(h: float, n: int, t: float = 0.25) -> list[tuple[float, float]]:
    """(x, expected ground height) written out riser by riser: n risers up T apart from
    x0, a landing L deep, n risers down T apart; sampled just before and after each riser
    and in the middle of each tread."""
    x0, land = STAIRS_X0_M, STAIR_LANDING_M
    up = [x0 + i * t for i in range(n)]                       # riser i up: to (i+1) h
    top_end = up[-1] + land                                   # the landing's far edge
    down = [top_end + i * t for i in range(n)]                # riser i down: to (n-1-i) h
    out = [(0.0, 0.0), (x0 - 0.05, 0.0)]
    for i, x in enumerate(up):
        out += [(x - EDGE, i * h), (x + EDGE, (i + 1) * h)]
        if i < n - 1:
            out.append((x + t / 2, (i + 1) * h))
    out.append((up[-1] + land / 2, n * h))
    for i, x in enumerate(down):
        out += [(x - EDGE, (n - i) * h), (x + EDGE, (n - 1 - i) * h)]
        if i < n - 1:
            out.append((x + t / 2, (n - 1 - i) * h))
    out.append((down[-1] + 0.2, 0.0))
    return out


@pytest.mark.parametrize(("h", "n", "t"), [(0.015, 3, None), (0.03, 1, None),
                                           (0.01, 5, None), (0.015, 3, 0.15)])
def test_the_ground_rises_and_falls_step_by_step(h: float, n: int, t: float | None) -> None:
    """Default treads (25 cm: ``t`` None) and given ones (``--stairs H,N,TREAD``)."""
    world = (World(stairs_height_m=h, stairs_count=n) if t is None
             else World(stairs_height_m=h, stairs_count=n, stairs_tread_m=t))
    model = build_mjcf(ROBOT, world=world).model()
    for y in (0.3, -0.3):                     # beside the robot's path, both sides
        for x, want in hand_profile(h, n, 0.25 if t is None else t):
            assert ground(model, x, y) == pytest.approx(want, abs=1e-9), (x, y)


def test_the_three_1_5_cm_steps_in_numbers() -> None:
    """The suite's stairs, by hand (25 cm treads): risers up at 0.30, 0.55, 0.80 m, the
    landing 4.5 cm high to 1.10 m, risers down at 1.10, 1.35, 1.60 m."""
    model = build_mjcf(ROBOT, world=World(stairs_height_m=0.015, stairs_count=3)).model()
    for x, want in [(0.29, 0.0), (0.31, 0.015), (0.56, 0.03), (0.81, 0.045), (1.09, 0.045),
                    (1.11, 0.03), (1.36, 0.015), (1.61, 0.0)]:
        assert ground(model, x, 0.3) == pytest.approx(want, abs=1e-9), x
    assert stairs_end_m(3) == pytest.approx(1.60)
    # and they end sideways where the world says
    inside, outside = STAIRS_HALF_WIDTH_M - EDGE, STAIRS_HALF_WIDTH_M + EDGE
    assert ground(model, 0.95, inside) == pytest.approx(0.045, abs=1e-9)
    assert ground(model, 0.95, outside) == pytest.approx(0.0, abs=1e-9)


def test_no_stairs_is_the_plain_scene() -> None:
    assert build_mjcf(ROBOT, world=World(stairs_height_m=0.0, stairs_count=0)).scene \
        == build_mjcf(ROBOT).scene


@pytest.mark.parametrize(("kwargs", "needle"), [
    ({"stairs_height_m": 0.06, "stairs_count": 3}, "World.stairs_height_m: 0.06 is outside"),
    ({"stairs_height_m": 0.015, "stairs_count": 11}, "World.stairs_count: 11 is not an"),
    ({"stairs_height_m": 0.015, "stairs_count": 0}, "give both above 0"),
    ({"stairs_height_m": 0.0, "stairs_count": 2}, "give both above 0"),
    ({"stairs_height_m": 0.015, "stairs_count": 3, "stairs_tread_m": 0.01},
     "World.stairs_tread_m: 0.01 is outside"),
])
def test_world_refuses_half_or_out_of_range_stairs(kwargs: dict, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle.replace("(", r"\(")):
        World(**kwargs)


def test_a_stairs_condition_gives_the_walk_option() -> None:
    c = Condition("stairs", "stairs", World(stairs_height_m=0.015, stairs_count=3))
    assert c.args == ("--stairs", "0.015,3")
