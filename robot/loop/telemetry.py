"""What the streaming loop reports: a per-tick snapshot and the statistics of a run."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from robot.bus.base import ServoState
from robot.imu.base import ImuSample
from robot.loop.latency import SampleStats


@dataclass
class Telemetry:
    """A snapshot of the loop for the CLI, the panel and recorders (joint order).

    state: "idle" | "ramp_in" | "waiting" (a chased show before its start timecode) |
    "walking" | "ramp_out" | "rest" | "pose" | "stopped" | "estop"; period_error_ms:
    lateness of the last tick start [ms]; clamped: the joints (names, joint order) held at
    a limit in this tick's command: by the source (the gait engine clamps what its IK asks
    beyond a limit) or by the loop (a feedback correction beyond one); empty when none
    was; imu: the balance stage's last IMU sample (None: no IMU in the run). t and t_read [s]
    are on the loop's clock (the wall clock on servos, the simulation's on the sim bus):
    t the tick's start, t_read when the last read-back's reply was in.
    """

    t: float = 0.0
    state: str = "idle"
    tick: int = 0
    q_cmd: list[float] = field(default_factory=list)
    q_present: list[float] | None = None
    servo: dict[int, ServoState] = field(default_factory=dict)
    period_error_ms: float = 0.0
    overruns: int = 0
    amplitude: float = 0.0
    stop_reason: str | None = None
    fresh: bool = False  # True on ticks that read the servos back
    t_read: float = 0.0
    clamped: tuple[str, ...] = ()
    imu: ImuSample | None = None


TickObserver = Callable[[Telemetry], None]


@dataclass
class LoopStats:
    """Loop statistics after a run. Period errors are tick-start lateness [ms].

    fault: the run ended on a fault (watchdog, exception, failed observer): exit code 1;
    holding: it ended with torque left on (``hold_at_end`` and no fault or emergency stop);
    estop: it ended by an emergency stop (torque off at once); torque: what the bus told
    of the servos' torque at the end (robot.loop.ending.TORQUE_STATES: "on", "off",
    "sent": torque off sent but not confirmed, "unknown": nothing could be sent);
    slew_limited: per joint (the map's order), the ticks whose goal the loop held to the
    servo's speed (max_speed_rad_s) because the source asked it to move faster.
    """

    ticks: int
    rate_hz: float
    duration_s: float
    achieved_hz: float
    period_error_p50_ms: float
    period_error_p99_ms: float
    period_error_max_ms: float
    overruns: int
    bus_errors: int
    wall_s: float
    stop_reason: str
    fault: bool = False
    holding: bool = False
    estop: bool = False
    torque: str = "off"
    slew_limited: tuple[int, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def loop_stats(lateness: SampleStats, *, ticks: int, rate_hz: float, duration_s: float,
               overruns: int, bus_errors: int, wall_s: float, stop_reason: str,
               fault: bool, holding: bool, estop: bool, torque: str,
               slew_limited: tuple[int, ...] = ()) -> LoopStats:
    """The statistics of a run from the tick-start lateness samples [s] and its counts."""
    return LoopStats(
        ticks=ticks, rate_hz=rate_hz, duration_s=duration_s, achieved_hz=ticks / duration_s,
        period_error_p50_ms=lateness.percentile(50) * 1e3,
        period_error_p99_ms=lateness.percentile(99) * 1e3,
        period_error_max_ms=max(lateness.max, 0.0) * 1e3 if lateness.count else 0.0,
        overruns=overruns, bus_errors=bus_errors, wall_s=wall_s, stop_reason=stop_reason,
        fault=fault, holding=holding, estop=estop, torque=torque, slew_limited=slew_limited)


class GaitClock:
    """Gait time for observers that act at a time of the gait (a push, a preset switch):
    the loop time [s] since the first tick whose state is "walking" (``t0``)."""

    def __init__(self) -> None:
        self.t0: float | None = None

    def __call__(self, tel: Telemetry) -> float | None:
        """The gait time [s] at this tick; None before the gait walks."""
        if self.t0 is None:
            if tel.state != "walking":
                return None
            self.t0 = tel.t
        return tel.t - self.t0
