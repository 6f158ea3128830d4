"""One emulated servo: a control table (bytearray) laid out by ``sim.emulator.control_tables``
(the manuals' tables, initial values included), and where its horn is (``horn`` [ticks]).
Protocol-agnostic: ``sim.emulator.dispatch`` calls :meth:`EmulatedServo.read` / :meth:`write`
(checked and applied in ``servo_write``) with raw addresses and bytes, and the instruction
methods (reg write / action, reboot, factory reset, clear multi-turn). EEPROM (below
``EEPROM_END``) survives unplugging; RAM comes back at its power-on values (so does a
reboot). Motion is lazy: :meth:`update` with the time [s] before touching the table moves
the horn by its mode (``servo_motion``, ``servo_dynamics``) and refreshes the read-backs.
Communication watchdog (``servo_status.BUS_WATCHDOG``): the chain calls :meth:`hear` for
every instruction packet addressed to the servo (its id, broadcast, or listed in a
sync/bulk packet); :meth:`update` trips it (goal := present where the gap ran out, register
-1, goal writes refused) and leaves torque as it was.
"""

from __future__ import annotations

from sim.emulator import servo_frame, servo_indirect, servo_motion, servo_write
from sim.emulator.control_tables import BAUD_CODES, DXL_SIGNED, EEPROM_END, TABLES, UNPRINTED, Entry
from sim.emulator.servo_models import MODELS
from sim.emulator.servo_spec import ServoSpec
from sim.emulator.servo_state import PROTOCOL_2, ServoDynamics, WriteError, byteorder
from sim.emulator.servo_status import BUS_WATCHDOG, ERROR_BITS, RETURN_DELAY_UNIT_S

__all__ = ["EmulatedServo", "ServoSpec"]

#: The registers that hold a family's position limits (low, high).
POSITION_LIMITS: dict[str, tuple[str, str]] = {
    "dynamixel_x": ("min_position_limit", "max_position_limit"),
    "dynamixel_p1": ("cw_angle_limit", "ccw_angle_limit"),
    "feetech_sts": ("min_angle_limit", "max_angle_limit"),
    "dynamixel_xl320": ("cw_angle_limit", "ccw_angle_limit"),
    "feetech_scs": ("min_angle_limit", "max_angle_limit"),
}


class EmulatedServo:
    """Control table plus the horn's motion model for one servo (``dynamics``: the chain's)."""
    dynamics: ServoDynamics | None = None

    def __init__(self, spec: ServoSpec, now: float) -> None:
        self.spec = spec
        self.model = MODELS[spec.model]
        self.family = self.model.family
        self.byteorder = byteorder(self.family)
        layout = self.model.layout                      # its control table's key
        self.table: dict[str, Entry] = TABLES[layout]
        self.mem = bytearray(max(r.address + r.size for r in self.table.values()))
        self.owner = bytearray(len(self.mem))  # 0: no register; else index+1
        self.regs = list(self.table.items())
        self._slots = {n: (e.address, e.address + e.size, self.family == "dynamixel_x" and n in
                           DXL_SIGNED, 1 << 8 * e.size) for n, e in self.regs}   # get / set_raw
        for i, (_, reg) in enumerate(self.regs):
            self.owner[reg.address:reg.address + reg.size] = bytes([i + 1]) * reg.size
        self.conditions: set[str] = set()   # injected hardware faults (names of ERROR_BITS)
        self.stuck = False                  # injected jam: the horn does not move
        self.frozen: set[str] = set()       # injected: registers that ignore host writes
        self.speed_tps = self.model.no_load_speed * self.model.ticks_per_rad
        self._p1_errors = 0   # Protocol 1.0 has no error register: the status byte only
        codes = {b: c for c, b in BAUD_CODES[self.family].items()}
        if spec.baud not in codes:
            raise ValueError(f"servo {spec.servo_id}: baud {spec.baud} is not a "
                             f"{self.family} rate; valid: {sorted(codes)}")
        values = {n: e.initial for n, e in self.table.items() if e.initial is not None}
        values.update({**UNPRINTED[layout], **self.model.initial})
        values.update(model_number=self.model.number, id=spec.servo_id,
                      baud_rate=codes[spec.baud], return_delay_time=spec.return_delay,
                      present_position=spec.zero_ticks, goal_position=spec.zero_ticks)
        low, high = POSITION_LIMITS[self.family]
        values.update({low: spec.min_ticks, high: spec.max_ticks})
        for name, v in values.items():
            self.set(name, v)
        self.horn = float(spec.zero_ticks)     # where the horn is [ticks, actual]
        self.step_target = self.horn            # STS step mode's target [ticks, actual]
        self.pinned: dict[str, int] = {}        # back-door values motion must not overwrite
        self._t = now
        self.watchdog = BUS_WATCHDOG[self.family]
        self.heard = now    # time of the last instruction packet addressed to this servo [s]
        self.eeprom_end = EEPROM_END[layout]   # EEPROM below, RAM from here
        self._saved = bytes(self.mem[:self.eeprom_end])   # EEPROM as kept over power-off
        self._ram_at_power_on = bytes(self.mem[self.eeprom_end:])
        self.pending: tuple[int, bytes] | None = None     # a Reg Write waiting for Action
        self._registered = {"dynamixel_x": "registered_instruction", "dynamixel_p1": "registered",
                            "dynamixel_xl320": "registered"}.get(self.family, "async_write_flag")
        self._indirect = servo_indirect.indirect_map(self.table)   # X only
        self.partner: EmulatedServo | None = None   # the other axis of a dual-axis case

    def get(self, name: str) -> int:
        """Value of a register by name (signed where the Dynamixel table says so)."""
        start, end, signed, _ = self._slots[name]
        return int.from_bytes(self.mem[start:end], self.byteorder, signed=signed)

    def set_raw(self, name: str, value: int) -> None:
        """Store a register by name, leaving the position model alone."""
        start, end, _, modulus = self._slots[name]
        self.mem[start:end] = (value % modulus).to_bytes(end - start, self.byteorder)

    def set(self, name: str, value: int) -> None:
        """Store a register by name without any check (the emulator's back door).
        ``present_position`` places the horn where the servo then reads ``value``."""
        self.set_raw(name, value)
        self._idle = False      # at rest with nothing set since the last motion step: False
        if name == "present_position":
            self.horn = float(servo_frame.actual_goal(self, self.get(name)))
            self.step_target = self.horn

    def pin(self, name: str, value: int) -> None:
        """Back door: store ``value``; a register motion computes then keeps it."""
        self.set(name, value)
        self.pinned.update({name: value} if name in servo_motion.COMPUTED else {})

    def snapshot(self) -> dict[str, int]:
        return {name: self.get(name) for name in self.table}

    @property
    def servo_id(self) -> int:
        return self.get("id")

    @property
    def baud(self) -> int | None:
        """The rate [bit/s] the servo listens at (from its baud_rate register)."""
        return BAUD_CODES[self.family].get(self.get("baud_rate"))

    @property
    def return_delay_s(self) -> float:
        return self.get("return_delay_time") * RETURN_DELAY_UNIT_S[self.family]

    @property
    def status_return_level(self) -> int:
        return self.get("status_return_level")

    @property
    def error_register(self) -> str:
        return "hardware_error_status" if "hardware_error_status" in self.table else "status"

    # ------------------------------------------------------------------ behaviour
    def hear(self, now: float) -> None:
        """An instruction packet addressed to this servo arrived at ``now`` [s]."""
        self.heard = now

    @property
    def watchdog_tripped(self) -> bool:
        wd = self.watchdog
        return wd is not None and self.get(wd.register) == wd.tripped

    def update(self, now: float, *, quiet_until: float = float("inf")) -> None:
        """Advance motion to ``now`` and the watchdog to ``quiet_until`` (silence seen) [s,
        time.monotonic()]."""
        self._assert_faults()
        wd = self.watchdog
        deadline = None if wd is None else wd.deadline(
            self.get(wd.register), torque_on=bool(self.get("torque_enable")), heard=self.heard)
        if wd is not None and deadline is not None and deadline < min(now, quiet_until):
            self._advance(max(deadline, self._t))
            self.hold()                                                      # stop there
            for name in ("goal_velocity", "goal_pwm"):     # in every mode (X: the one with it)
                self.set_raw(name, 0)
            self.set(wd.register, wd.tripped)
        self._advance(now)

    def _advance(self, now: float) -> None:
        dt = max(0.0, now - self._t)
        self._t = now
        if self._idle:           # at rest and nothing set since: the registers hold
            return
        self.horn = servo_motion.advance(self, self.horn, dt)
        for name, value in self.pinned.items():
            self.set_raw(name, value)
        self._idle = servo_motion.at_rest(self)

    def hold(self) -> None:
        """Goal := where the horn is (after a reset, power-on, mode change, multi-turn clear)."""
        self.set_raw("goal_position", servo_frame.goal_for(self, self.horn))
        self.step_target, self._idle = self.horn, False
        self._advance(self._t)

    def _assert_faults(self) -> None:
        bits = {name: bit for bit, name in ERROR_BITS[self.family].items()}
        value = 0
        for name in self.conditions:
            value |= 1 << bits[name]
        if self.family in PROTOCOL_2:
            # X series (and the XL-320) latch hardware errors until reboot and drop torque.
            value |= self.get("hardware_error_status")
            if value:
                self.set("torque_enable", 0)
        if self.family == "dynamixel_p1":
            self._p1_errors = value
            return
        self.set_raw(self.error_register, value)

    @property
    def error_bits(self) -> int:
        if self.family == "dynamixel_p1":
            return self._p1_errors
        return self.get(self.error_register)

    def read(self, address: int, length: int) -> bytes | None:
        """``length`` bytes from ``address``; None when the range leaves the table or holds
        no register at all (undefined address: the manual's Access Error). Indirect Data
        bytes read the byte their Indirect Address points at."""
        if address < 0 or length < 0 or address + length > len(self.mem):
            return None
        if length and not any(self.owner[address:address + length]):
            return None
        out = bytearray(self.mem[address:address + length])
        for i in range(length):
            target = servo_indirect.target(self._indirect, self.get, address + i)
            if target is not None:
                out[i] = self.mem[target]
        return bytes(out)

    def write(self, address: int, data: bytes) -> WriteError:
        """Apply a host write if every byte lands in whole, writable registers (Indirect
        Data bytes land where their Indirect Address points); all or nothing."""
        plans = []
        for run_address, run in servo_indirect.runs(self._indirect, self.get, address, data):
            err, values = servo_write.plan(self, run_address, run)
            if err is not WriteError.NONE:
                return err
            plans.append(values)
        for values in plans:
            servo_write.apply(self, values)
        if any(v.get("torque_enable") == servo_write.STS_CENTRE_COMMAND for v in plans):
            a, n = self.table["homing_offset"][:2]     # the firmware saves its new offset
            self._saved = self._saved[:a] + bytes(self.mem[a:a + n]) + self._saved[a + n:]
        if address < self.eeprom_end and self._keeps_eeprom():
            self._saved = bytes(self.mem[:self.eeprom_end])
        return WriteError.NONE

    # ------------------------------------------------------------------ instructions
    def reg_write(self, address: int, data: bytes) -> WriteError:
        """Reg Write: hold the write until Action; the flag register reads 1 meanwhile."""
        if address < 0 or address + len(data) > len(self.mem) or not data:
            return WriteError.ACCESS
        self.pending = (address, bytes(data))
        self.set(self._registered, 1)
        return WriteError.NONE

    def action(self) -> WriteError:
        """Action: execute the registered write, if any."""
        pending, self.pending = self.pending, None
        self.set(self._registered, 0)
        return WriteError.NONE if pending is None else self.write(*pending)

    def factory_reset(self, option: int) -> None:
        """X Factory Reset: 0xFF everything, 0x01 all but ID, 0x02 all but ID and baud."""
        keep = {0x01: ("id",), 0x02: ("id", "baud_rate")}.get(option, ())
        kept = {name: self.get(name) for name in keep}
        for name, e in self.table.items():
            self.set_raw(name, e.initial if e.initial is not None else 0)
        for name, v in {**UNPRINTED[self.model.layout], **self.model.initial,
                        "model_number": self.model.number, **kept}.items():
            self.set_raw(name, v)
        self._saved = bytes(self.mem[:self.eeprom_end])
        self.hold()

    def clear_multi_turn(self) -> None:
        """X Clear (multi-turn): present position back within one turn, while stopped."""
        if not self.get("moving"):
            self.horn = float(round(self.horn) % self.model.resolution)
            self.hold()

    def _keeps_eeprom(self) -> bool:
        """Whether an EEPROM write survives power-off: always on Dynamixel X; on Feetech
        STS only with the Lock flag (55) at 0 (1 = changes not saved, the factory value)."""
        return self.family in PROTOCOL_2 or self.get("lock") == 0

    def power_off(self, now: float) -> None:
        """Unplugged: the horn stops where it is and torque is gone."""
        self.update(now)
        self.set("torque_enable", 0)

    def follow(self, name: str, value: int) -> None:
        """The other axis of this case was given ``name`` = ``value`` (a setting the case
        shares): take it, in EEPROM too."""
        self.set(name, value)
        if self.table[name].address < self.eeprom_end and self._keeps_eeprom():
            self._saved = bytes(self.mem[:self.eeprom_end])

    def power_on(self, now: float) -> None:
        """Plugged in again: EEPROM as saved, RAM at its power-on values, horn unmoved."""
        self.update(now)
        self.mem[:self.eeprom_end] = self._saved
        self.mem[self.eeprom_end:] = self._ram_at_power_on
        self.horn = servo_frame.within_turn(self, self.horn)   # the turn count is not kept over power-off
        self.hold()
        self._t = self.heard = now

    def reboot(self) -> None:
        """Reboot: like a power cycle (RAM to its power-on values, latched errors gone)."""
        self.power_on(self._t)
        self.pending = None
        self._assert_faults()

