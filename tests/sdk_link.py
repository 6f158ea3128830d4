"""A vendor SDK's port and packet handler on an emulated chain, for the wire-level tests."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

import dynamixel_sdk as dxl
import scservo_sdk as scs

from sim.emulator.chain import Emulator


def served(protocol: str, ids: Sequence[int], baud: int) -> Iterator[tuple[Emulator, Any, Any]]:
    """Servos ``ids`` at ``baud`` [bit/s] and an open SDK port with its packet handler
    (dynamixel_sdk Protocol 2.0 / 1.0, scservo_sdk ``PacketHandler(0)``)."""
    sdk: Any = scs if protocol == "feetech" else dxl
    with Emulator(protocol, ids=list(ids), baud=baud) as emu:
        port = sdk.PortHandler(emu.port)
        assert port.openPort() and port.setBaudRate(baud)
        ph = (scs.PacketHandler(0) if sdk is scs
              else dxl.PacketHandler(1.0 if protocol == "dynamixel1" else 2.0))
        yield emu, port, ph
        port.closePort()


def ok(result: tuple[Any, ...]) -> Any:
    """The value of an SDK ``(value, comm, error)`` read that must succeed cleanly."""
    value, comm, error = result
    assert (comm, error) == (0, 0)
    return value
