"""Perturbed worlds on the sim bus (sim.mujoco.world): slope, bumps, pushes, latency, friction,
mass; each checked on the compiled model or the running physics, against an independent
computation (ray casts, momentum, sensors)."""

from __future__ import annotations

import math
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robot.bus.servo_map import ServoMap  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from robot.errors import ConfigError  # noqa: E402
from robot.loop.telemetry import Telemetry  # noqa: E402
from sim.mujoco.bus import MujocoBus  # noqa: E402
from sim.mujoco.mjcf import build_mjcf  # noqa: E402
from sim.mujoco.world import PUSH_WINDOW_S, Push, PushScheduler, World  # noqa: E402
from sim.mujoco.world_scene import (  # noqa: E402
    BUMP_COVER,
    BUMP_PREFIX,
    BUMPS_HALF_WIDTH_M,
    BUMPS_LENGTH_M,
    BUMPS_X0_M,
)

ROBOT = load_robot()
SM = ServoMap(ROBOT)
REST = SM.goals(SM.vector(ROBOT.rest))
G = 9.81  # [m/s^2], the model's gravity magnitude


def _floor_height(bus: MujocoBus, x: float, y: float) -> float:
    """z of the floor at (x, y) by a ray cast straight down onto the floor geom only."""
    m, d = bus.model, bus.data
    floor = m.geom("floor").id
    geomid = np.zeros(1, np.int32)
    top = 10.0
    dist = mujoco.mj_ray(m, d, np.array([x, y, top]), np.array([0.0, 0.0, -1.0]), None, 1,
                         m.body("torso").id, geomid)
    assert geomid[0] == floor
    return top - dist


@pytest.mark.parametrize(("slope", "cross"), [(5.0, 0.0), (-5.0, 0.0), (0.0, 4.0),
                                              (3.0, -2.0)])
def test_slope_tilts_the_floor_the_documented_way(slope: float, cross: float) -> None:
    with MujocoBus(ROBOT, world=World(slope_deg=slope, cross_slope_deg=cross)) as b:
        assert isinstance(b, MujocoBus)
        z0 = _floor_height(b, 0.0, 0.0)
        ahead, left = _floor_height(b, 1.0, 0.0) - z0, _floor_height(b, 0.0, 1.0) - z0
        # + slope: the ground rises 1 m ahead; + cross slope: it falls to the right (-y).
        assert z0 == pytest.approx(0.0, abs=1e-9)
        assert ahead == pytest.approx(math.tan(math.radians(slope)), abs=1e-9)
        assert left == pytest.approx(math.tan(math.radians(cross)), abs=1e-9)
        # Gravity along the walk (the floor's tangent in the x-z plane), from the geometry:
        # -g sin(slope) when walking uphill.
        tangent = np.array([1.0, 0.0, ahead]) / math.hypot(1.0, ahead)
        along = float(np.dot(b.model.opt.gravity, tangent))
        assert along == pytest.approx(-G * math.sin(math.atan(math.tan(math.radians(slope)))),
                                      abs=1e-6)
        # The floor geom's own normal agrees, and gravity itself is untouched.
        normal = b.data.geom_xmat[b.model.geom("floor").id].reshape(3, 3)[:, 2]
        np.testing.assert_allclose(normal, b.floor_normal, atol=1e-12)
        np.testing.assert_allclose(b.model.opt.gravity, [0.0, 0.0, -G])


@pytest.mark.parametrize(("slope", "cross"), [(5.0, 0.0), (0.0, 5.0)])
def test_robot_stands_on_a_5_deg_slope_for_1_s(slope: float, cross: float) -> None:
    world = World(slope_deg=slope, cross_slope_deg=cross)
    n = np.array(world.floor_normal())
    with MujocoBus(ROBOT, world=world) as b:
        assert isinstance(b, MujocoBus)
        for sole in ("r_sole", "l_sole"):          # placed on the plane: no drop
            assert float(np.dot(n, b.data.site(sole).xpos)) == pytest.approx(0.0, abs=1e-9)
        b.set_torque(ROBOT.ids, enabled=True)
        h0 = b.standing_height
        for k in range(1, 101):
            b.write_goals(REST)
            b.clock.sleep_until(k * 0.01)
            height = float(np.dot(n, b.base_pose()[0]))   # above the plane
            assert abs(height - h0) < 0.01 * h0, k
        assert b.contacts_feet() == (True, True)
        # Upright with respect to the floor (rigidly rotated with it), not fallen.
        z_axis = b.data.xmat[b.model.body("torso").id].reshape(3, 3)[:, 2]
        assert math.degrees(math.acos(float(np.dot(z_axis, n)))) < 3.0
        # The accelerometer sees gravity tilted with the robot (the floor tilts, not
        # gravity): standing still, it reads +g along world z in the IMU frame, about
        # g sin(slope) along x and g sin(cross slope) along y (both axes tilt uphill).
        accel = b.data.sensor("imu_accelerometer").data
        imu = b.data.site("imu").xmat.reshape(3, 3)
        np.testing.assert_allclose(accel, imu.T @ [0.0, 0.0, G], atol=0.1)
        assert accel[0] == pytest.approx(G * math.sin(math.radians(slope)), abs=0.4)
        assert accel[1] == pytest.approx(G * math.sin(math.radians(cross)), abs=0.4)


def _bumps(model: mujoco.MjModel) -> list[int]:
    return [g for g in range(model.ngeom)
            if (model.geom(g).name or "").startswith(BUMP_PREFIX)]


def test_bumps_are_deterministic_of_the_height_and_cover_a_quarter() -> None:
    a = build_mjcf(ROBOT, world=World(bumps_mm=8.0, terrain_seed=3)).model()
    again = build_mjcf(ROBOT, world=World(bumps_mm=8.0, terrain_seed=3)).model()
    other = build_mjcf(ROBOT, world=World(bumps_mm=8.0, terrain_seed=4)).model()
    ids = _bumps(a)
    assert len(ids) > 100
    np.testing.assert_array_equal(a.geom_pos[ids], again.geom_pos[_bumps(again)])
    np.testing.assert_array_equal(a.geom_size[ids], again.geom_size[_bumps(again)])
    assert not np.array_equal(a.geom_pos[ids[:50]], other.geom_pos[_bumps(other)[:50]])
    size, pos = a.geom_size[ids], a.geom_pos[ids]
    np.testing.assert_allclose(2 * size[:, 2], 0.008)           # 8 mm high
    np.testing.assert_allclose(pos[:, 2], 0.004)                # resting on the floor
    assert np.all((2 * size[:, :2] >= 0.03 - 1e-12) & (2 * size[:, :2] <= 0.08 + 1e-12))
    assert np.all(pos[:, 0] - size[:, 0] >= BUMPS_X0_M - 1e-12)
    assert np.all(pos[:, 0] + size[:, 0] <= BUMPS_X0_M + BUMPS_LENGTH_M + 1e-12)
    assert np.all(np.abs(pos[:, 1]) + size[:, 1] <= BUMPS_HALF_WIDTH_M + 1e-12)
    cover = float(np.sum(4 * size[:, 0] * size[:, 1])) / (
        BUMPS_LENGTH_M * 2 * BUMPS_HALF_WIDTH_M)
    assert cover == pytest.approx(BUMP_COVER, abs=0.03)
    # Boxes never overlap (one per cell), so the summed area is the covered area.
    gap = np.abs(pos[:, None, :2] - pos[None, :, :2]) - (size[:, None, :2] + size[None, :, :2])
    overlap = (gap < -1e-12).all(axis=2)
    np.fill_diagonal(overlap, False)
    assert not overlap.any()
    assert build_mjcf(ROBOT, world=World(bumps_mm=0.0, terrain_seed=3)).model().ngeom \
        == build_mjcf(ROBOT).model().ngeom                       # 0 mm: no bumps at all


def test_no_option_is_the_plain_model_and_the_same_simulation() -> None:
    plain, same = build_mjcf(ROBOT), build_mjcf(ROBOT, world=World())
    assert plain.scene == same.scene
    assert plain.scene == build_mjcf(ROBOT, world=World(bumps_mm=0.0, terrain_seed=7)).scene
    qpos = []
    for world in (None, World()):
        with MujocoBus(ROBOT, world=world) as b:
            assert isinstance(b, MujocoBus)
            b.set_torque(ROBOT.ids, enabled=True)
            b.write_goals(REST)
            b.clock.sleep_until(0.1)
            qpos.append(b.data.qpos.copy())
    np.testing.assert_array_equal(qpos[0], qpos[1])


def _momentum(bus: MujocoBus) -> np.ndarray:
    """Total linear momentum of the robot: subtree mass x centre-of-mass velocity."""
    m, d = bus.model, bus.data
    mujoco.mj_forward(m, d)
    mujoco.mj_subtreeVel(m, d)
    torso = m.body("torso").id
    return float(m.body_subtreemass[torso]) * d.subtree_linvel[torso].copy()


@pytest.mark.parametrize(("yaw_deg", "jx", "jy"), [(0.0, 1.0, 0.0), (90.0, 0.6, 0.3),
                                                   (-30.0, 0.0, -0.8)])
def test_a_push_changes_the_momentum_by_its_impulse_in_the_heading_frame(
        yaw_deg: float, jx: float, jy: float) -> None:
    """In the air without gravity the push is the only external force."""
    with MujocoBus(ROBOT) as b:
        assert isinstance(b, MujocoBus)
        m, d = b.model, b.data
        m.opt.gravity[:] = 0.0
        d.qpos[2] += 1.0
        half = math.radians(yaw_deg) / 2
        d.qpos[3:7] = [math.cos(half), 0.0, 0.0, math.sin(half)]
        p0 = _momentum(b)
        b.push(jx, jy)
        torso = m.body("torso").id
        assert np.linalg.norm(d.xfrc_applied[torso, :3]) == pytest.approx(
            math.hypot(jx, jy) / PUSH_WINDOW_S)
        b.clock.sleep_until(0.013)                     # mid-window: partial impulse
        b.clock.sleep_until(0.05)
        dp = _momentum(b) - p0
        assert np.all(d.xfrc_applied[torso] == 0.0)    # the force ended with its window
        yaw = math.radians(yaw_deg)
        expected = np.array([math.cos(yaw) * jx - math.sin(yaw) * jy,
                             math.sin(yaw) * jx + math.cos(yaw) * jy, 0.0])
        assert np.linalg.norm(dp - expected) <= 0.15 * np.linalg.norm(expected)


class _RecordingBus:
    def __init__(self) -> None:
        self.calls: list[tuple[float, float, float]] = []

    def push(self, jx: float, jy: float, *, window_s: float = PUSH_WINDOW_S) -> None:
        self.calls.append((jx, jy, window_s))


def test_push_scheduler_counts_gait_time_from_the_first_walking_tick() -> None:
    bus = _RecordingBus()
    sched = PushScheduler(bus, [Push(0.5, 0.0, -1.0), Push(0.02, 2.0, 0.0)])
    tel = Telemetry()
    for k in range(200):
        tel.t, tel.state = k * 0.01, "ramp_in" if k < 30 else "walking"
        sched(tel)
    assert sched.gait_t0 == pytest.approx(0.30)
    assert [(a.push.at_s, a.sim_t_s) for a in sched.applied] == [
        (0.02, pytest.approx(0.32)), (0.5, pytest.approx(0.80))]
    assert bus.calls == [(2.0, 0.0, PUSH_WINDOW_S), (0.0, -1.0, PUSH_WINDOW_S)]


def test_latency_delays_the_actuator_reference() -> None:
    j = SM.index("r_shoulder_pitch")
    q = SM.vector(ROBOT.rest)
    q[j] += 0.005                                      # within one step's slew
    goals = SM.goals(q)
    refs = {}
    for latency in (0.0, 0.02):
        with MujocoBus(ROBOT, world=World(latency_s=latency)) as b:
            assert isinstance(b, MujocoBus)
            act = b.model.actuator("r_shoulder_pitch").id
            b.set_torque(ROBOT.ids, enabled=True)
            before = float(b.data.ctrl[act])
            b.write_goals(goals)
            changed_at = None
            for k in range(1, 41):
                b.clock.sleep_until(k * 0.001)
                if changed_at is None and b.data.ctrl[act] != before:
                    changed_at = b.clock.now()
            refs[latency] = changed_at
    assert refs[0.0] == pytest.approx(0.001)           # the first step uses the new goal
    assert refs[0.02] == pytest.approx(0.021)          # ... 20 ms of sim time later


def test_friction_and_mass_scale_change_the_model() -> None:
    plain = MujocoBus(ROBOT)
    scaled = MujocoBus(ROBOT, world=World(friction_scale=0.5, mass_scale=1.5))
    with plain, scaled:
        a, b = plain.model, scaled.model
        np.testing.assert_allclose(b.geom_friction[:, 0], 0.5 * a.geom_friction[:, 0])
        np.testing.assert_array_equal(b.geom_friction[:, 1:], a.geom_friction[:, 1:])
        np.testing.assert_allclose(b.body_mass[1:], 1.5 * a.body_mass[1:])
        np.testing.assert_allclose(b.body_inertia[1:], 1.5 * a.body_inertia[1:])
        torso = a.body("torso").id
        assert b.body_subtreemass[torso] == pytest.approx(1.5 * a.body_subtreemass[torso])


@pytest.mark.parametrize(("kwargs", "needle"), [
    ({"slope_deg": 21.0}, "World.slope_deg: 21.0 is outside [-20, 20] deg"),
    ({"latency_s": 0.2}, "World.latency_s: 0.2 is outside [0, 0.1] s"),
    ({"friction_scale": 0.1}, "World.friction_scale: 0.1 is outside [0.2, 3]"),
    ({"mass_scale": float("nan")}, "World.mass_scale: nan is outside [0.5, 2]"),
    ({"terrain_seed": -1}, "World.terrain_seed: -1 is not an integer"),
])
def test_world_refuses_values_outside_their_range(kwargs: dict, needle: str) -> None:
    with pytest.raises(ConfigError, match=f"^{needle.replace('[', '.').replace(']', '.')}"):
        World(**kwargs)
    with pytest.raises(ConfigError, match="Push.jx: 11.0 is outside"):
        Push(1.0, 11.0, 0.0)
