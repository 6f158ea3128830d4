"""How long one control tick keeps a serial bus busy, and the highest rate it can carry.

Each byte is 10 bits on the wire (8N1). Per tick the loop sends one goal sync write; every
``read_every`` ticks it reads every servo's state block back. Packet sizes follow the
protocols' framing:

- Dynamixel Protocol 2.0: instruction = 10 bytes (header 4, id, length 2, instruction, CRC
  2) + parameters; status = 11 + data. Sync write = 14 + N x (1 + goal size) (design.md:
  14 + 5N); sync read = 14 + N, then N status packets, one after another.
- Dynamixel Protocol 1.0 and Feetech STS: instruction = 6 bytes (0xFF 0xFF, id, length,
  instruction, checksum) + parameters; status = 6 + data. Sync write = 8 + N x (1 + goal
  size) (Feetech 8 + 3N); Feetech sync read = 8 + N then N status packets; Protocol 1.0
  (AX) has no sync read: one 8-byte read and its status per servo.

Each status packet also waits its servo's Return Delay Time. With absolute deadlines a
tick that runs long is absorbed by the next ones while the average fits (write + read /
read_every per tick) and the read tick itself stays under two periods (else a whole slot
is missed: an overrun). ``TickWire.max_rate_hz`` is the rate where both just hold, on the
wire alone (the host and the USB adapter add their own latency on top).
``robot.bus.rate_check`` refuses a rate a bus cannot carry.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Bits per byte on the wire (start, 8 data, stop).
BITS_PER_BYTE = 10
#: Framing per family: (instruction overhead, status overhead, sync-packet address+length
#: field bytes, has sync read) [bytes].
FRAMING: dict[str, tuple[int, int, int, bool]] = {
    "dynamixel_x": (10, 11, 4, True),
    "dynamixel_xl320": (10, 11, 4, True),    # the same Protocol 2.0 framing
    "dynamixel_p1": (6, 6, 2, False),
    "feetech_sts": (6, 6, 2, True),
    "feetech_scs": (6, 6, 2, True),          # the same Feetech framing
}


@dataclass(frozen=True)
class TickWire:
    """Bytes and seconds one tick puts on the wire.

    baud [bit/s]; write_bytes: the goal sync write; read_bytes: one state read of every
    servo (instructions and status packets); read_delay_s: the servos' return delays in
    that read [s]; read_every: ticks per state read.
    """

    baud: int
    servos: int
    write_bytes: int
    read_bytes: int
    read_delay_s: float
    read_every: int

    @property
    def write_s(self) -> float:
        return self.write_bytes * BITS_PER_BYTE / self.baud

    @property
    def read_s(self) -> float:
        return self.read_bytes * BITS_PER_BYTE / self.baud + self.read_delay_s

    @property
    def min_period_s(self) -> float:
        """The shortest tick period the wire allows [s]."""
        return max(self.write_s + self.read_s / self.read_every,
                   (self.write_s + self.read_s) / 2)

    @property
    def max_rate_hz(self) -> float:
        return 1.0 / self.min_period_s


def tick_wire(family: str, *, servos: int, baud: int, goal_size: int, block_size: int,
              read_every: int, return_delay_s: float = 0.0) -> TickWire:
    """The wire per tick of a ``family`` bus with ``servos`` servos at ``baud`` [bit/s]:
    goal registers of ``goal_size`` bytes, a state block of ``block_size`` bytes read every
    ``read_every`` ticks, each servo answering ``return_delay_s`` [s] late."""
    inst, status, fields, sync_read = FRAMING[family]
    write = inst + fields + servos * (1 + goal_size)
    reply = status + block_size
    if sync_read:
        read = inst + fields + servos + servos * reply
    else:
        read = servos * (inst + fields + reply)
    return TickWire(baud, servos, write, read, servos * return_delay_s, max(1, read_every))
