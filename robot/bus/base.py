"""The servo-bus interface every backend implements (Dynamixel, Feetech, MuJoCo).

Buses speak ticks and servo ids only; radians live in ``robot.bus.servo_map``.
Backends do no I/O in their constructor: ``open()`` (or ``with bus:``) connects.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import TracebackType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    from robot.bus.servo_map import ServoMap
    from robot.bus.wire_time import TickWire


@dataclass(frozen=True)
class ServoInfo:
    """What a scan learns about one servo.

    id: bus id; model: model number; model_name: datasheet name; firmware: firmware
    version; return_delay_us: configured return delay [µs]; baud: baud rate it answered at.
    """

    id: int
    model: int
    model_name: str
    firmware: int | None = None
    return_delay_us: float | None = None
    baud: int | None = None


@dataclass(frozen=True)
class ServoState:
    """One servo's read-back.

    position: present position [ticks]; load: signed load [% of max torque];
    temperature: [°C]; voltage: [V]; errors: normalised hardware-error names
    ("overheating", "overload", "voltage", "encoder", "electrical_shock", "overcurrent").
    """

    id: int
    position: int
    load: float | None = None
    temperature: float | None = None
    voltage: float | None = None
    errors: frozenset[str] = field(default_factory=frozenset)


class Bus(ABC):
    """A chain of servos. Use as a context manager; ``close()`` turns torque off."""

    #: "dynamixel" | "dynamixel1" | "feetech" | "lx" | "sim"
    kind: str = "abstract"

    @abstractmethod
    def open(self) -> None:
        """Connect (open the port / start the simulation). Raises BusError with a fix."""

    @abstractmethod
    def close(self, *, torque_off: bool = True) -> None:
        """Disconnect; by default disable torque on every known servo first. Idempotent."""

    @property
    @abstractmethod
    def is_open(self) -> bool: ...

    @property
    def retry_span_s(self) -> float:
        """The longest one transaction with all its retries can keep a servo from hearing
        any packet [s] (a partial sync-read retry addresses only the silent servos). The
        servos' own bus watchdog must be armed longer than this. 0 for buses without one."""
        return 0.0

    @abstractmethod
    def ping(self, servo_id: int) -> int | None:
        """Model number of ``servo_id``, or None if it does not answer."""

    @abstractmethod
    def scan(self, ids: Iterable[int]) -> list[ServoInfo]:
        """Every servo among ``ids`` that answers, in id order."""

    @abstractmethod
    def set_torque(self, ids: Iterable[int], *, enabled: bool) -> None:
        """Enable or disable torque on ``ids``."""

    @abstractmethod
    def write_goals(self, goals: Mapping[int, int]) -> None:
        """Goal positions [ticks] for many servos as ONE sync-write packet."""

    def write_joint_goals(self, servo_map: ServoMap, q: npt.NDArray[np.float64]) -> None:
        """Every servo of ``servo_map`` to the joint angles ``q`` [rad] (its joint order):
        ``write_goals(servo_map.goals(q))``, what the loop sends each tick. The sim bus
        takes the vector whole (``ServoMap.tick_vector``: the same ticks, no dict)."""
        self.write_goals(servo_map.goals(q.tolist()))

    @abstractmethod
    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        """Present state of ``ids`` by sync read. Raises BusError naming a missing id."""

    def arm_failsafe(self, ids: Iterable[int], *, timeout_s: float) -> float | None:
        """Arm the servos' own communication watchdog: if no packet arrives for
        ``timeout_s`` [s] they stop moving. Returns the timeout actually armed [s] (rounded
        to the servo's unit), or None when the servos have no such watchdog.

        This default is for buses without one (the MuJoCo bus): it does nothing.
        """
        return None

    def failsafe_tripped(self, ids: Iterable[int]) -> list[int]:
        """Which of ``ids`` have their armed watchdog tripped (they then refuse goals until
        it is disarmed). This default is for buses without one: none."""
        return []

    def disarm_failsafe(self, ids: Iterable[int]) -> None:
        """Disarm it (and clear a tripped watchdog) so the servos accept goals again; no-op
        when there is none. This default is for buses without one: it does nothing."""
        return None

    def max_rate_hz(self, *, read_every: int) -> float | None:
        """The fastest control rate the wire carries with a read-back every ``read_every``
        ticks [Hz]; None when the wire sets no practical limit (the default)."""
        return None

    def check_rate(self, rate_hz: float, *, read_every: int) -> None:
        """ConfigError when the wire cannot carry goals at ``rate_hz`` [Hz] with a read-back
        every ``read_every`` ticks (the LX bus: one packet per servo). Default: any rate."""
        return None

    def release(self, ids: Iterable[int]) -> None:
        """Torque off on ``ids`` at once, in one packet that needs no reply where the bus
        allows (an emergency, or a bus that stopped answering); confirm with
        ``set_torque(ids, enabled=False)`` while the bus answers. Default: ``set_torque``."""
        self.set_torque(ids, enabled=False)

    #: The servos' longest return delay as measured when the bus opened [s] (0: unknown).
    return_delay_s: float = 0.0

    def tick_wire(self, read_every: int) -> TickWire | None:
        """What one control tick puts on the wire (robot.bus.wire_time), reading the state
        back every ``read_every`` ticks; None for buses without a serial wire (this
        default)."""
        return None

    def read_gains(self, servo_id: int, *, model: int | None = None) -> dict[str, int] | None:
        """The position-control gain registers of ``servo_id`` [register values, named as in
        robot/servo/gains.py], by its joint's servo model (else by ``model``, its model
        number); None when the model is unknown or the bus has no gain registers (this
        default, for buses without them)."""
        return None

    def read_positions(self, ids: Iterable[int]) -> dict[int, int]:
        """Present positions [ticks] of ``ids``."""
        return {i: s.position for i, s in self.read_state(ids).items()}

    def __enter__(self) -> Bus:
        self.open()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def bus_rate(bus: Bus, rate_hz: float = 200.0, *, read_every: int = 10) -> float:
    """``rate_hz`` [Hz], or the fastest the bus's wire carries if that is lower (an LX
    chain: no sync write), for loops whose rate the user did not choose (holding a pose)."""
    top = bus.max_rate_hz(read_every=read_every)
    return rate_hz if top is None else min(rate_hz, float(int(top)))
