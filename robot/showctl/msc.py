"""MIDI Show Control (the MIDI 1.0 MSC recommended practice, RP-002): a System Exclusive
message ``F0 7F <device> 02 <command format> <command> <data> F7``. Of its commands biped
answers GO (01) and STOP (02): GO with a cue number fires that cue of the cue list, GO
without one the cue after the last fired; STOP is a safe stop. The data of both is the cue
number in ASCII (digits and '.'), optionally followed by 00 and the cue list, 00 and the
cue path. Device ids: 0-111 one device, 112-126 groups, 127 all-call (always answered).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

UNIVERSAL_REALTIME = 0x7F
MSC_SUB_ID = 0x02
ALL_CALL = 0x7F
COMMANDS = {0x01: "go", 0x02: "stop"}


@dataclass(frozen=True)
class MscCommand:
    """``command``: "go" or "stop"; ``cue``: its cue number (None: none given);
    ``cue_list``: the cue list named (None)."""

    command: str
    cue: str | None = None
    cue_list: str | None = None


@dataclass(frozen=True)
class NotMsc:
    """A System Exclusive message biped does not act on, and why (``kind`` logs once)."""

    kind: str
    why: str


def _field(data: bytes) -> str | None:
    return data.decode("ascii", errors="replace") or None


def parse_msc(data: Sequence[int], *, device: int) -> MscCommand | NotMsc | None:
    """The MSC command in a SysEx message's ``data`` (the bytes between F0 and F7, as mido
    gives them); None: a SysEx that is not MSC, or is for another device."""
    if len(data) < 4 or data[0] != UNIVERSAL_REALTIME or data[2] != MSC_SUB_ID:
        return None
    if data[1] not in (device, ALL_CALL):
        return None
    if len(data) < 5:
        return NotMsc("msc short", "MSC: a message without a command")
    command = COMMANDS.get(data[4])
    if command is None:
        return NotMsc(f"msc {data[4]:02X}", f"MSC command {data[4]:02X}h: biped answers "
                      "GO (01h) and STOP (02h) only")
    parts = bytes(data[5:]).split(b"\x00")
    cue = _field(parts[0])
    if cue is not None and not all(c.isdigit() or c == "." for c in cue):
        return NotMsc("msc cue", f"MSC {command.upper()}: cue number {cue!r} is not digits "
                      "and '.'")
    return MscCommand(command, cue, _field(parts[1]) if len(parts) > 1 else None)
