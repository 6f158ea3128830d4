"""The simulated IMU (``[imu] kind = "sim"``): MuJoCo's gyro, accelerometer and framequat
sensors at the ``imu`` site on the torso (the body tree's ``imu`` frame, robot/body/boxes.py
for the box model; the sensors: ``sim.mujoco.mjcf_robot``; the site's axes are the
torso's), made to look like a BNO055: white noise, a constant bias and latency.

Measurement model, per axis, in the IMU (device) frame (the torso frame rotated by
``mount_rpy_deg``, so noise and bias belong to the chip's axes, as on a real robot)::

    gyro  = true + b_g + n_g,   b_g ~ N(0, (bias * GYRO_OFFSET)^2)  drawn once at open()
    accel = true + b_a + n_a,   b_a ~ N(0, (bias * ACCEL_OFFSET)^2)
    n ~ N(0, (noise * density * sqrt(bandwidth))^2), fresh for every new measurement
    quat  = true ⊗ exp(n_q / 2),  n_q ~ N(0, (noise * QUAT_NOISE)^2) per axis   (fusion)

The densities and offsets are the BNO055 datasheet's typical values (BST-BNO055-DS000
rev 1.4, section 1 "Specification", Tables 0-1/0-2), the bandwidths the chip's filters in
fusion mode (Table 3-7, default sensor configuration). All randomness
comes from ``numpy.random.default_rng(seed)``: the same seed and the same reads give the
same samples.

Latency: every ``read()`` takes a measurement of the present physics state (``data.time``)
into a small buffer and returns the newest buffered one that is at least ``latency_ms``
old (before that much time has passed: the oldest). Its ``t`` is when it was taken. The
buffer holds only what a later read may still need, so its resolution is the read period:
reads every 5 ms with latency 10 ms return exactly the sample of 10 ms ago; with latency
7 ms, the one of 10 ms ago. MuJoCo computes sensors at the start of each physics step, so
the freshest reading is up to one timestep (2 ms) older than ``data.time`` besides.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import mujoco
import numpy as np

from robot.config.imu_file import ImuConfig
from robot.errors import BipedError, ConfigError
from robot.imu.base import STANDARD_GRAVITY, Imu, ImuError, ImuSample, Quat
from robot.imu.frames import Mount, quat_mul, quat_normalize

#: Sensor names in the MJCF (sim/mjcf_robot.add_actuators_and_sensors) and their sizes.
SENSORS = {"gyro": ("imu_gyro", 3), "accel": ("imu_accelerometer", 3),
           "quat": ("imu_orientation", 4)}
#: Gyro output noise density 0.014 deg/s/sqrt(Hz) [rad/s/sqrt(Hz)].
GYRO_NOISE_DENSITY = math.radians(0.014)
#: Gyro filter bandwidth in fusion mode (GYR_Config_0 default: 32 Hz) [Hz].
GYRO_BANDWIDTH_HZ = 32.0
#: Accelerometer output noise density 150 ug/sqrt(Hz) [m/s^2/sqrt(Hz)].
ACCEL_NOISE_DENSITY = 150e-6 * STANDARD_GRAVITY
#: Accelerometer filter bandwidth in fusion mode (ACC_Config default: 62.5 Hz) [Hz].
ACCEL_BANDWIDTH_HZ = 62.5
#: Gyro zero-rate offset, typical +-1 deg/s [rad/s] (one standard deviation of b_g).
GYRO_OFFSET = math.radians(1.0)
#: Accelerometer zero-g offset, typical +-80 mg [m/s^2] (one standard deviation of b_a).
ACCEL_OFFSET = 0.080 * STANDARD_GRAVITY
#: Orientation noise of the fused quaternion per axis [rad]: an estimate (the datasheet
#: gives no figure), small next to the tilt a biped balances against.
QUAT_NOISE = math.radians(0.1)
#: Per-sample standard deviations at noise = 1.
GYRO_SIGMA = GYRO_NOISE_DENSITY * math.sqrt(GYRO_BANDWIDTH_HZ)     # ~1.4e-3 rad/s
ACCEL_SIGMA = ACCEL_NOISE_DENSITY * math.sqrt(ACCEL_BANDWIDTH_HZ)  # ~1.2e-2 m/s^2
_TIME_EPS = 1e-9  # [s]


class SimImu(Imu):
    """The IMU of the robot simulated by ``bus`` (a ``sim.mujoco.bus.MujocoBus``; open the
    bus before the IMU), with the noise, bias and latency of ``config``."""

    kind = "sim"

    def __init__(self, bus: Any, config: ImuConfig) -> None:
        self.bus = bus
        self.config = config
        self._mount = Mount.from_rpy_deg(config.mount_rpy_deg)
        self._level = self._mount.is_identity   # the chip's axes are the torso's
        self._adr: dict[str, int] | None = None
        self._buffer: deque[ImuSample] = deque()
        self._rng = np.random.default_rng(config.seed)
        self._gyro_bias = (0.0, 0.0, 0.0)
        self._accel_bias = (0.0, 0.0, 0.0)
        self._normals = _Normals(self._rng)

    @property
    def is_open(self) -> bool:
        return self._adr is not None

    def open(self) -> None:
        if self._adr is not None:
            return
        try:
            model = self.bus.model
        except BipedError as e:
            raise ImuError(f"sim imu: {e}") from e
        adr: dict[str, int] = {}
        for key, (name, dim) in SENSORS.items():
            sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
            if sid < 0 or model.sensor_dim[sid] != dim:
                raise ImuError(f"sim imu: the MuJoCo model has no {dim}-axis sensor {name!r} "
                               "(sim/mujoco/mjcf_robot.py adds it at the 'imu' site)")
            adr[key] = int(model.sensor_adr[sid])
        c = self.config
        self._rng = np.random.default_rng(c.seed)
        self._gyro_bias = _tuple3(self._rng.normal(0.0, c.bias * GYRO_OFFSET, 3))
        self._accel_bias = _tuple3(self._rng.normal(0.0, c.bias * ACCEL_OFFSET, 3))
        self._normals = _Normals(self._rng)
        self._buffer.clear()
        self._adr = adr

    def close(self) -> None:
        self._adr = None
        self._buffer.clear()

    def exact(self) -> ImuSample:
        """The noise-free, bias-free measurement of the present state, in the torso frame
        (for tests and metrics; the robot should use ``read``)."""
        a = self._adr
        if a is None:
            raise ImuError("sim imu: not open; call open() (or use `with`) first")
        d = self.bus.data
        s = d.sensordata.tolist()
        g, c, q = a["gyro"], a["accel"], a["quat"]
        return ImuSample(d.time, (s[g], s[g + 1], s[g + 2]), (s[c], s[c + 1], s[c + 2]),
                         (s[q], s[q + 1], s[q + 2], s[q + 3]) if self.config.fusion else None)

    def read(self) -> ImuSample:
        """The newest sample at least ``latency_ms`` old (module docstring), torso frame."""
        now = self.exact()
        buf = self._buffer
        if buf and now.t < buf[-1].t - _TIME_EPS:   # the simulation was reset
            buf.clear()
        if not buf or now.t > buf[-1].t + _TIME_EPS:
            buf.append(self._measure(now))
        due = now.t - self.config.latency_ms / 1000.0 + _TIME_EPS
        while len(buf) > 1 and buf[1].t <= due:
            buf.popleft()
        return buf[0] if self._level else self._mount.to_torso(buf[0])

    def _measure(self, exact: ImuSample) -> ImuSample:
        """What the chip reports for ``exact`` (torso frame): in its own frame, with bias
        and a fresh draw of noise."""
        dev = exact if self._level else self._mount.to_imu(exact)
        c = self.config
        if c.noise == 0.0 and c.bias == 0.0:
            return dev
        draw = self._normals.three
        gyro = _noisy(dev.gyro, self._gyro_bias, c.noise * GYRO_SIGMA, draw())
        accel = _noisy(dev.accel, self._accel_bias, c.noise * ACCEL_SIGMA, draw())
        quat = dev.quat
        if quat is not None and c.noise > 0.0:
            sigma = c.noise * QUAT_NOISE
            x, y, z = draw()
            quat = quat_normalize(quat_mul(quat, _small_rotation((sigma * x, sigma * y,
                                                                   sigma * z))))
        return ImuSample(dev.t, gyro, accel, quat)


def open_sim_imu(config: ImuConfig, *, bus: Any = None) -> SimImu:
    """The ``sim`` IMU plugin (entry point group ``biped.imus``, see pyproject.toml)."""
    if bus is None or getattr(bus, "kind", None) != "sim":
        where = "no bus" if bus is None else f"the {getattr(bus, 'kind', '?')} bus"
        raise ConfigError(f"imu.kind: \"sim\" reads the MuJoCo simulation and needs the sim "
                          f"bus (--bus sim), got {where}; on a real robot set [imu] kind to "
                          "its device (e.g. \"bno055\")")
    return SimImu(bus, config)


class _Normals:
    """Standard normal draws from ``rng``, three at a time, drawn in blocks: the same
    numbers in the same order as drawing three per call (numpy's Generator fills a block
    from its stream one value after the other), without a numpy call per sample."""

    BLOCK = 3 * 4096

    def __init__(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._buf: list[float] = []
        self._i = 0

    def three(self) -> tuple[float, float, float]:
        i = self._i
        if i + 3 > len(self._buf):
            self._buf, i = self._rng.standard_normal(self.BLOCK).tolist(), 0
        self._i = i + 3
        b = self._buf
        return b[i], b[i + 1], b[i + 2]


def _noisy(v: tuple[float, float, float], bias: tuple[float, float, float], sigma: float,
           z: tuple[float, float, float]) -> tuple[float, float, float]:
    """(v + bias) + sigma * z, per axis (the order numpy's normal(0, sigma) adds in)."""
    return (v[0] + bias[0] + sigma * z[0], v[1] + bias[1] + sigma * z[1],
            v[2] + bias[2] + sigma * z[2])


def _tuple3(v: Any) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _small_rotation(rotvec: tuple[float, float, float]) -> Quat:
    """Quaternion of the rotation vector ``rotvec`` [rad]."""
    x, y, z = rotvec
    angle = math.sqrt(x * x + y * y + z * z)
    if angle == 0.0:
        return (1.0, 0.0, 0.0, 0.0)
    s = math.sin(angle / 2) / angle
    return (math.cos(angle / 2), x * s, y * s, z * s)
