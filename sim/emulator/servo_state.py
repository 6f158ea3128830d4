"""What the servo's helpers (``servo_motion``, ``servo_write``) see of an emulated servo.

A leaf module: ``sim.emulator.servo`` builds on it, the helpers use only it, so no module
imports ``servo`` back. :class:`ServoState` is the part of ``EmulatedServo`` they touch.
"""

from __future__ import annotations

import enum
from typing import Literal, Protocol

from sim.emulator.control_tables import DXL_SIGNED, TABLES, Entry
from sim.emulator.servo_dynamics import ServoDynamics
from sim.emulator.servo_model import ServoModel
from sim.emulator.servo_status import BusWatchdog


class WriteError(enum.Enum):
    """Why a write was refused; each codec maps it to its protocol's error code."""

    NONE = 0
    ACCESS = 1       # read-only, unknown or EEPROM-while-torque-on address
    RANGE = 2        # value outside the register's allowed range
    LIMIT = 3        # goal outside the position limits
    LENGTH = 4       # the write covers part of a register


class ServoState(Protocol):
    """One servo's table and settings, as the motion and write checks use them.

    mem: the control table's bytes; owner: per byte, 0 (no register) or the index + 1 of
    its register in ``regs``; regs: the table's (name, entry) rows in order; frozen: names
    whose host writes are acknowledged but not stored (an injected fault); table: name ->
    entry; horn: where the horn actually is [ticks, before any offset, several turns in
    the multi-turn modes]; step_target: where STS step mode takes it [ticks, actual].
    """

    family: str
    model: ServoModel
    stuck: bool
    frozen: set[str]
    speed_tps: float
    mem: bytearray
    owner: bytearray
    regs: list[tuple[str, Entry]]
    table: dict[str, Entry]
    horn: float
    step_target: float
    eeprom_end: int
    watchdog: BusWatchdog | None
    #: the servo model moving it in position modes (None: constant-speed travel)
    dynamics: ServoDynamics | None

    @property
    def watchdog_tripped(self) -> bool: ...

    def get(self, name: str) -> int: ...

    def set(self, name: str, value: int) -> None: ...

    def set_raw(self, name: str, value: int) -> None: ...

    def hold(self) -> None: ...

    @property
    def partner(self) -> ServoState | None:
        """The other axis of a dual-axis case (2XL430-W250), else None."""

    def follow(self, name: str, value: int) -> None:
        """Take a setting the other axis of the case was given (kept in EEPROM)."""


#: Where a family has no rule of its own it behaves as its kin: the XL-320 as the AX
#: (CW/CCW Angle Limits, Moving Speed in 0.111 rev/min, bit-10 directions), the Feetech SCS
#: as the STS (goals clamped to the angle limits, a goal write energises, sign-magnitude
#: feedback). What Protocol 2.0 brings (latched hardware errors, the alert bit, EEPROM
#: locked while torque is on) goes by ``PROTOCOL_2``.
KIN: dict[str, str] = {"dynamixel_xl320": "dynamixel_p1", "feetech_scs": "feetech_sts"}
PROTOCOL_2 = frozenset({"dynamixel_x", "dynamixel_xl320"})
#: Byte order of multi-byte registers: the SCSCL table is big-endian (its END(2) reads 1).
BYTE_ORDER: dict[str, Literal["little", "big"]] = {"feetech_scs": "big"}


def kin(family: str) -> str:
    """The family whose behaviour ``family`` shares where it has none of its own."""
    return KIN.get(family, family)


def byteorder(family: str) -> Literal["little", "big"]:
    return BYTE_ORDER.get(family, "little")


def decode_value(family: str, address: int, data: bytes) -> int:
    """A written value as the log shows it: in the family's byte order, signed for signed
    registers (only the X table has any)."""
    signed = family == "dynamixel_x" and any(
        reg.address == address and reg.size == len(data) and name in DXL_SIGNED
        for name, reg in TABLES[family].items())
    return int.from_bytes(data, byteorder(family), signed=signed)
