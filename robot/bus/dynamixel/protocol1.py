"""ROBOTIS Dynamixel on Protocol 1.0 (AX-12A, AX-18A, MX-28 / MX-64 / MX-106 on 1.0
firmware) through ``dynamixel_sdk``.

Control table: ``tables.DYNAMIXEL_P1`` (ROBOTIS e-Manual, AX-12A). Protocol 1.0 has sync
write (goals go out in one packet, as on the other buses) but no sync read on the AX
series, so ``read_state`` reads the block present_position .. present_temperature
(8 bytes) from each servo in turn; a silent servo is a BusError naming its joint.

The status packet's error byte carries the servo's condition on every reply: bits 1
(angle limit), 3 (range), 4 (checksum) and 6 (instruction) mean the instruction was
refused; bits 0 (voltage), 2 (overheating) and 5 (overload) are hardware faults, reported
in ``ServoState.errors``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

import dynamixel_sdk

from robot.bus.base import ServoState
from robot.bus.dynamixel.protocol2 import _Port
from robot.bus.sdk.bus import SdkBus
from robot.bus.sdk.port import error_names, sign_magnitude

#: Status error bits that mean "instruction refused" (angle limit, range, checksum,
#: instruction); the others (voltage, overheating, overload) are conditions.
REFUSED_BITS = (1 << 1) | (1 << 3) | (1 << 4) | (1 << 6)
#: Present Load / Present Speed: bit 10 is the direction (CW), bits 0-9 the magnitude.
DIRECTION_BIT = 10


class Dynamixel1Bus(SdkBus):
    """Dynamixel Protocol 1.0 chain. ``Dynamixel1Bus(port, baud=..., robot=..., ...)``.

    Load is Present Load [0.1 % of max torque, signed by direction], voltage [0.1 V],
    temperature [°C].
    """

    kind = "dynamixel1"
    family = "dynamixel_p1"
    families = ("dynamixel_p1",)
    sdk = dynamixel_sdk
    port_class = _Port
    firmware_register = "firmware_version"

    def _make_packet_handler(self) -> Any:
        return dynamixel_sdk.PacketHandler(1.0)

    def _status_failed(self, error: int) -> bool:
        return bool(error & REFUSED_BITS)

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        first, last = (self.table[n] for n in self.state_block)
        length = last.address + last.size - first.address
        out: dict[int, ServoState] = {}
        for sid in dict.fromkeys(ids):
            block, status = self._transact("read state", sid, self._reader_for(sid, length))
            if len(block) < length:
                raise self._error(sid, "read state", f"short reply ({len(block)} of {length} "
                                  "bytes)", self.sdk.COMM_RX_CORRUPT)
            out[sid] = self._decode_state(sid, bytes(block), status)
        return out

    def _reader_for(self, sid: int, length: int) -> Callable[[], tuple[Any, int, int]]:
        start = self.table[self.state_block[0]].address
        return lambda: self._ph.readTxRx(self._port, sid, start, length)  # type: ignore[no-any-return]

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
        return ServoState(
            id=sid,
            position=self.field(block, "present_position"),
            load=sign_magnitude(self.field(block, "present_load"), DIRECTION_BIT) * 0.1,
            temperature=float(self.field(block, "present_temperature")),
            voltage=self.field(block, "present_voltage") * 0.1,
            errors=error_names(self.family, status & ~REFUSED_BITS),
        )
