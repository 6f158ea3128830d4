"""The simulated IMU on the MuJoCo bus: frames and signs, noise, bias, latency, seeds."""

from __future__ import annotations

import math
from collections.abc import Iterator

import mujoco
import numpy as np
import pytest

from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.imu import ImuConfig, ImuError, TiltEstimator, open_imu, tilt_from_accel, tilt_from_quat
from robot.imu.frames import quat_conj, quat_from_rpy, quat_rotate
from sim.mujoco.bus import MujocoBus
from sim.mujoco.imu import ACCEL_SIGMA, GYRO_SIGMA, SimImu

EXACT = ImuConfig(kind="sim", noise=0.0, bias=0.0, latency_ms=0.0)


@pytest.fixture(scope="module")
def robot() -> RobotConfig:
    return load_robot()


@pytest.fixture
def bus(robot: RobotConfig) -> Iterator[MujocoBus]:
    with MujocoBus(robot) as b:
        yield b


def stand(bus: MujocoBus, seconds: float = 0.5) -> None:
    """Torque on at the home pose and let the robot settle."""
    bus.set_torque(bus.robot.ids, enabled=True)
    bus.clock.sleep_until(bus.clock.now() + seconds)


def pose_in_air(bus: MujocoBus, rpy: tuple[float, float, float],
                omega: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
    """Torso at orientation ``rpy`` [rad], body rates ``omega`` [rad/s] (the free joint's
    angular velocity is in the torso frame), 1 m up, accelerations zero: mj_inverse then
    computes the sensors of exactly that state."""
    m, d = bus.model, bus.data
    d.qpos[2] += 1.0
    d.qpos[3:7] = quat_from_rpy(*rpy)
    d.qvel[:] = 0.0
    d.qvel[3:6] = omega
    d.qacc[:] = 0.0
    mujoco.mj_inverse(m, d)


def test_upright_and_still_reads_gravity_up_and_no_tilt(bus: MujocoBus) -> None:
    stand(bus)
    cfg = ImuConfig(kind="sim", bias=0.0)   # datasheet noise, no offsets
    with open_imu(cfg, bus=bus) as imu:
        samples = []
        for _ in range(50):
            bus.clock.sleep_until(bus.clock.now() + 0.005)
            samples.append(imu.read())
    # Standing on servos the torso leans a little; the IMU sees exactly that lean.
    _, q_base = bus.base_pose()
    base = tilt_from_quat(tuple(q_base))
    assert abs(base.roll) < 0.03 and abs(base.pitch) < 0.03
    up = quat_rotate(quat_conj(tuple(q_base)), (0.0, 0.0, 9.81))
    accel = np.mean([s.accel for s in samples], axis=0)
    assert accel == pytest.approx(up, abs=0.03)
    assert np.linalg.norm(accel) == pytest.approx(9.81, abs=0.03)
    assert np.std([s.accel[2] for s in samples]) < 5 * ACCEL_SIGMA
    assert np.abs(np.mean([s.gyro for s in samples], axis=0)).max() < 0.01
    s = samples[-1]
    assert s.quat is not None
    for tilt in (tilt_from_quat(s.quat), tilt_from_accel(tuple(accel))):
        assert tilt.roll == pytest.approx(base.roll, abs=0.005)
        assert tilt.pitch == pytest.approx(base.pitch, abs=0.005)


@pytest.mark.parametrize("rpy", [(0.0, 0.3, 0.0), (0.0, -0.3, 0.0), (0.25, 0.0, 0.0),
                                 (-0.2, 0.35, 1.2)])
def test_tilt_of_a_posed_torso(bus: MujocoBus, rpy: tuple[float, float, float]) -> None:
    with SimImu(bus, EXACT) as imu:
        pose_in_air(bus, rpy)
        s = imu.read()
    assert s.quat is not None
    assert s.quat == pytest.approx(quat_from_rpy(*rpy), abs=1e-9)
    g = -bus.model.opt.gravity
    assert s.accel == pytest.approx(quat_rotate(quat_conj(s.quat), tuple(g)), abs=1e-9)
    for tilt in (tilt_from_quat(s.quat), tilt_from_accel(s.accel)):
        assert tilt.roll == pytest.approx(rpy[0], abs=1e-9)
        assert tilt.pitch == pytest.approx(rpy[1], abs=1e-9)


def test_positive_pitch_is_nose_down(bus: MujocoBus) -> None:
    """+0.3 rad about +y: the torso's forward axis points below the horizon, the
    framequat-derived pitch is +0.3 and the accelerometer's x is negative."""
    with SimImu(bus, EXACT) as imu:
        pose_in_air(bus, (0.0, 0.3, 0.0))
        s = imu.read()
    forward = bus.data.xmat[bus.model.body("torso").id].reshape(3, 3)[:, 0]
    assert forward[2] == pytest.approx(-math.sin(0.3))
    assert s.quat is not None and tilt_from_quat(s.quat).pitch == pytest.approx(0.3)
    assert s.accel[0] < -2.0


def test_gyro_reads_the_body_rates(bus: MujocoBus) -> None:
    with SimImu(bus, EXACT) as imu:
        pose_in_air(bus, (0.1, -0.2, 0.5), omega=(0.1, -0.2, 0.3))
        assert imu.read().gyro == pytest.approx((0.1, -0.2, 0.3), abs=1e-12)
        # Sign: spinning about +y (nose going down) in free flight raises the pitch.
        pose_in_air(bus, (0.0, 0.0, 0.0), omega=(0.0, 0.5, 0.0))
        bus.model.opt.gravity[:] = 0.0
        for _ in range(50):
            mujoco.mj_step(bus.model, bus.data)
        s = imu.read()
    assert s.gyro[1] == pytest.approx(0.5, abs=1e-3)
    assert s.quat is not None
    assert tilt_from_quat(s.quat).pitch == pytest.approx(0.5 * 50 * bus.model.opt.timestep,
                                                         abs=2e-3)


def test_noise_zero_gives_the_exact_sensor_values(bus: MujocoBus) -> None:
    stand(bus, 0.1)
    with SimImu(bus, EXACT) as imu:
        adr = {n: bus.model.sensor(n).adr[0] for n in
               ("imu_gyro", "imu_accelerometer", "imu_orientation")}
        for _ in range(20):
            bus.clock.sleep_until(bus.clock.now() + 0.003)
            s, raw = imu.read(), bus.data.sensordata
            assert s.t == bus.data.time
            assert s.gyro == tuple(raw[adr["imu_gyro"]:adr["imu_gyro"] + 3])
            assert s.accel == tuple(raw[adr["imu_accelerometer"]:adr["imu_accelerometer"] + 3])
            assert s.quat == tuple(raw[adr["imu_orientation"]:adr["imu_orientation"] + 4])


def test_latency_returns_the_sample_from_latency_ago(bus: MujocoBus) -> None:
    period, latency = 0.0025, 0.010
    lag = round(latency / period)
    cfg = ImuConfig(kind="sim", noise=0.0, bias=0.0, latency_ms=latency * 1000)
    with SimImu(bus, cfg) as imu:
        truth, got = [], []
        for _ in range(40):   # the robot falls limp: the readings change every step
            bus.clock.sleep_until(bus.clock.now() + period)
            truth.append(imu.exact())
            got.append(imu.read())
            assert imu.read() == got[-1]   # a second read at the same time: same sample
    for i, s in enumerate(got):
        want = truth[max(0, i - lag)]
        assert s == want
        if i >= lag:
            assert bus.data.time - (len(got) - 1 - i) * period - s.t == pytest.approx(latency)


def test_noise_and_bias_statistics(bus: MujocoBus) -> None:
    stand(bus, 0.2)
    cfg = ImuConfig(kind="sim", noise=1.0, bias=0.0, latency_ms=0.0, seed=1)
    with SimImu(bus, cfg) as imu:
        err = []
        for _ in range(600):
            bus.clock.sleep_until(bus.clock.now() + 0.002)
            s, e = imu.read(), imu.exact()
            err.append(np.subtract(s.gyro + s.accel, e.gyro + e.accel))
    std = np.std(err, axis=0)
    assert std[:3] == pytest.approx([GYRO_SIGMA] * 3, rel=0.15)
    assert std[3:] == pytest.approx([ACCEL_SIGMA] * 3, rel=0.15)
    biased = ImuConfig(kind="sim", noise=0.0, bias=1.0, latency_ms=0.0, seed=1)
    with SimImu(bus, biased) as imu:
        offsets = set()
        for _ in range(5):
            bus.clock.sleep_until(bus.clock.now() + 0.002)
            s, e = imu.read(), imu.exact()
            offsets.add(tuple(np.round(np.subtract(s.gyro, e.gyro), 12)))
    assert len(offsets) == 1                          # a constant bias
    assert 0 < np.abs(next(iter(offsets))).max() < math.radians(5)


def run(robot: RobotConfig, cfg: ImuConfig) -> list[tuple[float, ...]]:
    with MujocoBus(robot) as b, SimImu(b, cfg) as imu:
        out = []
        for _ in range(20):
            b.clock.sleep_until(b.clock.now() + 0.004)
            s = imu.read()
            assert s.quat is not None
            out.append((s.t, *s.gyro, *s.accel, *s.quat))
        return out


def test_same_seed_same_samples(robot: RobotConfig) -> None:
    cfg = ImuConfig(kind="sim", seed=7)
    assert run(robot, cfg) == run(robot, cfg)
    assert run(robot, cfg) != run(robot, ImuConfig(kind="sim", seed=8))


def test_mount_is_transparent_in_the_torso_frame(bus: MujocoBus) -> None:
    turned = ImuConfig(kind="sim", noise=0.0, bias=0.0, latency_ms=0.0,
                       mount_rpy_deg=(180.0, 0.0, 90.0))
    with SimImu(bus, turned) as imu:
        pose_in_air(bus, (0.1, 0.2, 0.0), omega=(0.3, 0.0, -0.1))
        s, e = imu.read(), imu.exact()
    assert s.gyro == pytest.approx(e.gyro, abs=1e-12)
    assert s.accel == pytest.approx(e.accel, abs=1e-12)
    assert s.quat == pytest.approx(e.quat, abs=1e-12)


def test_without_fusion_tilt_comes_from_the_filter(bus: MujocoBus) -> None:
    stand(bus, 0.2)
    cfg = ImuConfig(kind="sim", fusion=False, seed=3)
    est = TiltEstimator()
    with open_imu(cfg, bus=bus) as imu:
        for _ in range(200):
            bus.clock.sleep_until(bus.clock.now() + 0.005)
            s = imu.read()
            assert s.quat is None
            tilt = est.update(s)
    # Standing: the filter's tilt is the accelerometer offset's (a few degrees at most).
    assert abs(tilt.roll) < 0.15 and abs(tilt.pitch) < 0.15


def test_errors(robot: RobotConfig) -> None:
    closed = MujocoBus(robot)
    with pytest.raises(ImuError, match="sim imu: sim bus: not open"):
        SimImu(closed, EXACT).open()
    with pytest.raises(ImuError, match="not open"):
        SimImu(closed, EXACT).read()
    with pytest.raises(ConfigError, match="needs the sim bus"):
        open_imu(ImuConfig(kind="sim"), bus=None)
