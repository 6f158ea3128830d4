"""The IMU interface every backend implements (simulated sensor, BNO055, plugins).

Frames: every sample is in the robot's torso frame (the pelvis frame, REP-103: x forward,
y left, z up); a backend rotates its device frame into it with the configured mounting
(``robot.imu.frames.Mount``). Backends do no I/O in their constructor: ``open()`` (or
``with imu:``) connects.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from types import TracebackType
from typing import NamedTuple

from robot.errors import BipedError

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

#: Standard gravity [m/s^2] (what an upright, still accelerometer reads on z).
STANDARD_GRAVITY = 9.80665


class ImuError(BipedError):
    """An IMU could not be opened or read: names the device (kind, port) and a fix."""


class ImuSample(NamedTuple):
    """One IMU measurement, in the torso frame (REP-103: x forward, y left, z up).

    t: time the measurement was taken, on the clock of the bus or host [s] (with latency it
    is older than ``now``); gyro: angular velocity of the torso in the torso frame [rad/s]
    (right-hand rule: +z turns left); accel: specific force in the torso frame [m/s^2]
    (gravity included: upright and still it reads (0, 0, +9.81)); quat: orientation of the
    torso frame in the world frame (w, x, y, z), unit norm, when the device fuses
    orientation on chip (world z up; the heading reference is the device's), else None.
    """

    t: float
    gyro: Vec3
    accel: Vec3
    quat: Quat | None = None


class Imu(ABC):
    """An inertial measurement unit. Use as a context manager (``with imu:``)."""

    #: "sim" | "bno055" | a plugin's name
    kind: str = "abstract"

    @abstractmethod
    def open(self) -> None:
        """Connect (open the port, configure the device / resolve the sim sensors).
        Raises ImuError naming the device and a fix. Idempotent."""

    @abstractmethod
    def close(self) -> None:
        """Disconnect. Idempotent."""

    @property
    @abstractmethod
    def is_open(self) -> bool: ...

    @abstractmethod
    def read(self) -> ImuSample:
        """The latest sample in the torso frame. Raises ImuError (one line) if the device
        does not answer; never blocks longer than the backend's documented timeout."""

    def __enter__(self) -> Imu:
        self.open()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
