"""An IMU that remembers its last sample: what the balance stage read this tick, for the
run's recorders (``Telemetry.imu``; an MCAP ``/imu`` channel), without a second read."""

from __future__ import annotations

from robot.imu.base import Imu, ImuSample


class LastSample(Imu):
    """``imu`` as it is; ``last``: the sample its last ``read`` returned (None before)."""

    def __init__(self, imu: Imu) -> None:
        self.imu = imu
        self.kind = imu.kind
        self.last: ImuSample | None = None

    def open(self) -> None:
        self.imu.open()

    def close(self) -> None:
        self.imu.close()

    @property
    def is_open(self) -> bool:
        return self.imu.is_open

    def read(self) -> ImuSample:
        self.last = self.imu.read()
        return self.last
