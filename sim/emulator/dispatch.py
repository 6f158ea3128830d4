"""One instruction dispatch for both wire protocols (Dynamixel 2.0 and Feetech STS).

The codecs (``sim.emulator.dxl_protocol``, ``sim.emulator.sts_protocol``) only frame packets and describe
their protocol in a :class:`Protocol`; what an instruction does to the servos that hear it,
who answers and at which status return level lives here, so the two cannot drift.

Instruction codes are the same numbers in both protocols (Feetech's is a Protocol-1 clone);
each protocol lists the ones it has. Ping answers at every status return level; reads from
``level_read`` (Dynamixel 1, STS 0: "0 = reply to read and ping only"); everything else from
``level_all``. Broadcast packets get no status, except ping (every servo answers, in id
order) and the fast reads (one combined packet).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import NamedTuple

from sim.emulator.servo import EmulatedServo
from sim.emulator.servo_state import WriteError, decode_value
from sim.emulator.wire import Handled, Reply, chain_replies, sync_write

PING, READ, WRITE, REG_WRITE, ACTION, FACTORY_RESET, REBOOT, CLEAR = 1, 2, 3, 4, 5, 6, 8, 0x10
SYNC_READ, SYNC_WRITE, FAST_SYNC_READ = 0x82, 0x83, 0x8A
BULK_READ, BULK_WRITE, FAST_BULK_READ = 0x92, 0x93, 0x9A
NAMES: dict[int, str] = {
    PING: "ping", READ: "read", WRITE: "write", REG_WRITE: "reg_write", ACTION: "action",
    FACTORY_RESET: "factory_reset", REBOOT: "reboot", CLEAR: "clear",
    SYNC_READ: "sync_read", SYNC_WRITE: "sync_write", FAST_SYNC_READ: "fast_sync_read",
    BULK_READ: "bulk_read", BULK_WRITE: "bulk_write", FAST_BULK_READ: "fast_bulk_read",
}
FastReply = Callable[[Mapping[int, EmulatedServo], list[tuple[int, int, int]]], list[Reply]]


class Protocol(NamedTuple):
    """What differs between the protocols, as data and three small functions.

    status(id, error, params) -> packet; alert(servo) -> error bits every status carries;
    ping_params(servo) -> ping reply params; write_errors: WriteError -> error code (0: the
    protocol has none); access_error / instruction_error: codes (0 / None: none, and an
    unknown instruction then gets no reply); addr_width: address/length field [bytes].
    """

    family: str
    instructions: frozenset[int]
    broadcast_id: int
    addr_width: int
    level_read: int
    level_all: int
    status: Callable[[int, int, bytes], bytes]
    alert: Callable[[EmulatedServo], int]
    ping_params: Callable[[EmulatedServo], bytes]
    write_errors: Mapping[WriteError, int]
    access_error: int
    instruction_error: int | None
    fast_reply: FastReply | None = None


def _word(b: bytes) -> int:
    return int.from_bytes(b, "little")


def read_status(p: Protocol, servo: EmulatedServo, address: int, length: int) -> bytes:
    """A read's status: the data, or ``length`` zeros with the access error."""
    data = servo.read(address, length)
    err = p.alert(servo) | (0 if data is not None else p.access_error)
    return p.status(servo.servo_id, err, data if data is not None else bytes(length))


def handle(p: Protocol, servo_id: int, inst: int, params: bytes,
           hearing: Mapping[int, EmulatedServo]) -> Handled:
    """Execute one instruction on the servos that hear it; return log fields and replies."""
    name = NAMES.get(inst, f"unknown_0x{inst:02x}") if inst in p.instructions else (
        f"unknown_0x{inst:02x}")
    servo = hearing.get(servo_id)
    broadcast = servo_id == p.broadcast_id
    targets = list(hearing.values()) if broadcast else ([servo] if servo else [])
    replies: list[Reply] = []
    ids: tuple[int, ...] = (servo_id,)
    address: int | None = None
    length: int | None = None
    values: dict[int, int] = {}
    w = p.addr_width

    def before(s: EmulatedServo) -> tuple[int, int, float]:
        """What the reply to a write uses: id, level and delay as they were (a new one
        takes effect after the reply)."""
        return s.servo_id, s.status_return_level, s.return_delay_s

    def reply(s: EmulatedServo, was: tuple[int, int, float], err: int, level: int) -> None:
        sid, srl, delay = was
        if not broadcast and srl >= level:
            replies.append(Reply(sid, p.status(sid, err | p.alert(s), b""), delay))

    def status_of(outcome: WriteError) -> int:
        return p.write_errors.get(outcome, 0)

    if inst not in p.instructions:
        if servo is not None and p.instruction_error is not None:
            reply(servo, before(servo), p.instruction_error, p.level_read)
    elif inst == PING:
        for s in sorted(targets, key=lambda s: s.servo_id):
            packet = p.status(s.servo_id, p.alert(s), p.ping_params(s))
            replies.append(Reply(s.servo_id, packet, s.return_delay_s))
    elif inst == READ and len(params) == 2 * w:
        address, length = _word(params[:w]), _word(params[w:])
        if servo is not None and servo.status_return_level >= p.level_read:
            replies.append(Reply(servo_id, read_status(p, servo, address, length),
                                 servo.return_delay_s))
    elif inst in (WRITE, REG_WRITE) and len(params) > w:
        address, data = _word(params[:w]), params[w:]
        length = len(data)
        values[servo_id] = decode_value(servo.family if servo else p.family, address, data)
        for s in targets:
            was = before(s)
            outcome = s.write(address, data) if inst == WRITE else s.reg_write(address, data)
            reply(s, was, status_of(outcome), p.level_all)
    elif inst == ACTION:
        for s in targets:
            was = before(s)
            reply(s, was, status_of(s.action()), p.level_all)
    elif inst in (REBOOT, FACTORY_RESET, CLEAR) and servo is not None:
        reply(servo, before(servo), 0, p.level_all)       # the status goes out first
        if inst == REBOOT:
            servo.reboot()
        elif inst == FACTORY_RESET:
            servo.factory_reset(params[0] if params else 0xFF)
        else:
            servo.clear_multi_turn()
    elif inst in (SYNC_READ, FAST_SYNC_READ) and len(params) >= 2 * w:
        address, length = _word(params[:w]), _word(params[w:2 * w])
        ids = tuple(params[2 * w:])
        items = [(sid, address, length) for sid in ids]
        replies = _reads(p, inst == FAST_SYNC_READ, hearing, items)
    elif inst == SYNC_WRITE and len(params) >= 2 * w:
        address, length = _word(params[:w]), _word(params[w:2 * w])
        values = sync_write(p.family, address, length, params[2 * w:], hearing)
        ids = tuple(values)
    elif inst in (BULK_READ, FAST_BULK_READ):
        items = [(params[i], _word(params[i + 1:i + 3]), _word(params[i + 3:i + 5]))
                 for i in range(0, len(params) - 4, 5)]
        ids = tuple(sid for sid, _, _ in items)
        values = {sid: a for sid, a, _ in items}   # per-id start address
        replies = _reads(p, inst == FAST_BULK_READ, hearing, items)
    elif inst == BULK_WRITE:
        i = 0
        while i + 5 <= len(params):
            sid, a, n = params[i], _word(params[i + 1:i + 3]), _word(params[i + 3:i + 5])
            values[sid] = decode_value(hearing[sid].family if sid in hearing else p.family, a,
                                       params[i + 5:i + 5 + n])
            if sid in hearing:
                hearing[sid].write(a, params[i + 5:i + 5 + n])
            i += 5 + n
        ids = tuple(values)
    return Handled(name, ids, address, values, length, replies)


def _reads(p: Protocol, fast: bool, hearing: Mapping[int, EmulatedServo],
           items: list[tuple[int, int, int]]) -> list[Reply]:
    if fast and p.fast_reply is not None:
        return p.fast_reply(hearing, items)
    return chain_replies(hearing, items, lambda s, a, n: read_status(p, s, a, n))
