"""The LX bus servo protocol on the servo side (HiWonder/LewanSoul "Bus Servo
Communication Protocol"; commands in ``sim.emulator.lx_commands``).

Packet: ``55 55 | id | length | command | params | checksum``, length = params + 3,
checksum = ~(id + length + command + params) & 0xFF; words little-endian. Only read
commands are answered, with the same command number and the value as parameters; a
packet to the broadcast id 254 is executed by every servo and answered by none, except ID
read, which every servo answers: with more than one on the bus the answers collide (here
the lines are modelled as a wired AND: the bytes combine and the checksum fails). A
packet whose length does not match its command is ignored, as is a value outside the
manual's range (assumption: the manual gives ranges, not what happens outside them).
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulator.lx_commands import (
    BROADCAST_ID,
    COMMANDS,
    HEADER,
    MOTOR_SPEED_RANGE,
    NAMES,
    OFFSET_RANGE,
    POSITION_MAX,
    TEMP_LIMIT_RANGE,
    VIN_RANGE_MV,
)
from sim.emulator.lx_servo import LxServo
from sim.emulator.wire import FrameParser, Handled, Reply

__all__ = ["BROADCAST_ID", "NAMES", "SERVO", "Parser", "handle"]
SERVO = LxServo          # the servo class the chain server builds for this protocol
PREFIX_LEN = 4           # 55 55 id length


def checksum(body: bytes) -> int:
    return ~sum(body) & 0xFF


def packet(servo_id: int, code: int, params: bytes = b"") -> bytes:
    body = bytes([servo_id, len(params) + 3, code]) + params
    return HEADER + body + bytes([checksum(body)])


class Parser(FrameParser):
    header = HEADER
    prefix_len = PREFIX_LEN

    def total_length(self, prefix: bytes) -> int | None:
        if prefix[2] == HEADER[0] or prefix[3] < 3:     # 55 55 55: the header is one later
            return None
        return prefix[3] + 3

    def decode(self, data: bytes) -> tuple[int, int, bytes] | None:
        if checksum(data[2:-1]) != data[-1]:
            return None
        return data[2], data[4], data[5:-1]


def _u16(b: bytes, i: int = 0) -> int:
    return int.from_bytes(b[i:i + 2], "little")


def _s16(b: bytes, i: int = 0) -> int:
    return int.from_bytes(b[i:i + 2], "little", signed=True)


def _words(*values: int) -> bytes:
    return b"".join((v & 0xFFFF).to_bytes(2, "little") for v in values)


def _answer(s: LxServo, code: int) -> bytes:
    """The parameters of read command ``code``'s answer."""
    f = s.f
    return {
        2: lambda: _words(f["goal_position"], f["move_time_ms"]),
        8: lambda: _words(f["wait_position"], f["wait_time_ms"]),
        14: lambda: bytes([f["id"]]),
        19: lambda: bytes([f["angle_offset"] & 0xFF]),
        21: lambda: _words(f["min_angle_limit"], f["max_angle_limit"]),
        23: lambda: _words(f["min_vin_mv"], f["max_vin_mv"]),
        25: lambda: bytes([f["temperature_limit"]]),
        26: lambda: bytes([f["present_temperature"]]),
        27: lambda: _words(f["present_voltage_mv"]),
        28: lambda: _words(s.position),
        30: lambda: bytes([f["motor_mode"], 0]) + _words(f["motor_speed"]),
        32: lambda: bytes([f["torque_enable"]]),
        34: lambda: bytes([f["led_ctrl"]]),
        36: lambda: bytes([f["led_error"]]),
    }[code]()


def _write(s: LxServo, code: int, p: bytes) -> int | None:
    """Apply write command ``code`` to ``s``; the value written (for the log), None if
    ignored."""
    f = s.f
    if code == 1 and _u16(p) <= POSITION_MAX:
        s.move(_u16(p), _u16(p, 2))
        return _u16(p)
    if code == 7 and _u16(p) <= POSITION_MAX:
        f["wait_position"], f["wait_time_ms"] = _u16(p), _u16(p, 2)
        return _u16(p)
    if code == 11:
        s.move(f["wait_position"], f["wait_time_ms"])
        return f["wait_position"]
    if code == 12:
        s.stop()
        return 0
    simple = {13: ("id", (0, BROADCAST_ID - 1)), 24: ("temperature_limit", TEMP_LIMIT_RANGE),
              33: ("led_ctrl", (0, 1)), 35: ("led_error", (0, 7))}
    if code in simple:
        name, (lo, hi) = simple[code]
        if not lo <= p[0] <= hi:
            return None
        f[name] = p[0]
        s.keep()
        return p[0]
    if code == 17:
        v = int.from_bytes(p[:1], "little", signed=True)
        if not OFFSET_RANGE[0] <= v <= OFFSET_RANGE[1]:
            return None
        s.adjust_offset(v)
        return v
    if code == 18:
        f["saved_offset"] = f["angle_offset"]
        s.keep()
        return f["angle_offset"]
    if code in (20, 22):
        lo, hi = _u16(p), _u16(p, 2)
        top = (0, POSITION_MAX) if code == 20 else VIN_RANGE_MV
        if not top[0] <= lo < hi <= top[1]:
            return None
        keys = ("min_angle_limit", "max_angle_limit") if code == 20 else ("min_vin_mv",
                                                                          "max_vin_mv")
        f[keys[0]], f[keys[1]] = lo, hi
        s.keep()
        return lo
    if code == 29 and p[0] in (0, 1) and \
            MOTOR_SPEED_RANGE[0] <= _s16(p, 2) <= MOTOR_SPEED_RANGE[1]:
        f["motor_mode"], f["motor_speed"] = p[0], _s16(p, 2)
        return p[0]
    if code == 31 and p[0] in (0, 1):
        s.load(bool(p[0]))
        return p[0]
    return None


def _collide(replies: list[bytes]) -> bytes:
    """Answers sent at once on one wire: a wired AND of their bytes."""
    out = bytearray(max(len(r) for r in replies))
    out[:] = b"\xff" * len(out)
    for r in replies:
        for i, b in enumerate(r):
            out[i] &= b
    return bytes(out)


def handle(servo_id: int, code: int, params: bytes,
           hearing: Mapping[int, LxServo]) -> Handled:
    """Execute one packet on the servos that hear it; return log fields and answers."""
    spec = COMMANDS.get(code)
    name = NAMES.get(code, f"unknown_{code}")
    broadcast = servo_id == BROADCAST_ID
    targets = list(hearing.values()) if broadcast else (
        [hearing[servo_id]] if servo_id in hearing else [])
    values: dict[int, int] = {}
    replies: list[Reply] = []
    if spec is None or len(params) + 3 != spec[1]:
        return Handled(name, (servo_id,), None, values, None, replies)
    if spec[2] is None:
        for s in targets:
            v = _write(s, code, params)
            if v is not None:
                values[s.servo_id] = v
    elif broadcast and code == 14:
        answers = [packet(s.servo_id, code, _answer(s, code)) for s in targets]
        if answers:
            replies.append(Reply(BROADCAST_ID, _collide(answers), 0.0))
    elif not broadcast:
        replies = [Reply(s.servo_id, packet(s.servo_id, code, _answer(s, code)), 0.0)
                   for s in targets]
    return Handled(name, (servo_id,), None, values, None, replies)
