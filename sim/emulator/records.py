"""What the emulator's parent and child exchange: the chain to serve, the packet log's
records, and the error the emulator raises."""

from __future__ import annotations

from dataclasses import dataclass, field

from robot.errors import BipedError
from sim.emulator.servo import ServoSpec
from sim.emulator.servo_dynamics import DynamicsSpec


class EmulatorError(BipedError):
    """The emulator was misused or its child process failed."""


@dataclass(frozen=True)
class Packet:
    """One received instruction packet.

    t: reception time [s, time.monotonic()]; instruction: "ping", "read", "write",
    "reboot", "sync_read", "sync_write", "fast_sync_read", "bulk_read", ...; ids: target
    ids in packet order; address: start address (None for ping/reboot/bulk); values:
    written value per id (writes), start address per id (bulk read), else empty;
    length: data length [bytes] where the instruction has one.
    """

    t: float
    instruction: str
    ids: tuple[int, ...]
    address: int | None
    values: dict[int, int] = field(default_factory=dict)
    length: int | None = None


@dataclass(frozen=True)
class ChainSpec:
    """The chain to serve; ``plugged``: indices into ``servos`` on the bus (None: all);
    ``dynamics``: each servo's model, in ``servos`` order (empty: constant-speed travel)."""

    protocol: str
    servos: tuple[ServoSpec, ...]
    seed: int = 0
    plugged: tuple[int, ...] | None = None
    dynamics: tuple[DynamicsSpec | None, ...] = ()
