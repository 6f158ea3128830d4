"""What an emulated servo reports about itself and how it times out, from the manuals.

The emulator's own transcription (the driver's ``robot.bus.tables`` holds the same facts
for the host side; ``tests/test_emulator_tables.py`` makes the two agree). Names of the
error bits are the normalised fault names both sides use (``Emulator.set_faults(hw_error=)``
takes them).
"""

from __future__ import annotations

from dataclasses import dataclass

#: Bit position -> fault name, per family.
ERROR_BITS: dict[str, dict[int, str]] = {
    # ROBOTIS e-Manual, XL430-W250, "Hardware Error Status(70)": bit 0 Input Voltage
    # Error, bit 2 Overheating Error, bit 3 Motor Encoder Error, bit 4 Electrical Shock
    # Error, bit 5 Overload Error (bits 1, 6, 7 unused on the XL430).
    "dynamixel_x": {0: "voltage", 2: "overheating", 3: "encoder", 4: "electrical_shock",
                    5: "overload"},
    # ROBOTIS e-Manual, "Protocol 1.0", Status Packet, Error byte: bit 0 Input Voltage,
    # 1 Angle Limit, 2 Overheating, 3 Range, 4 Checksum, 5 Overload, 6 Instruction
    # (dynamixel_sdk protocol1_packet_handler ERRBIT_* agree).
    "dynamixel_p1": {0: "voltage", 1: "angle_limit", 2: "overheating", 3: "range",
                     4: "checksum", 5: "overload", 6: "instruction"},
    # Feetech STS/SMS memory table, "Servo status(65)": bit 0 voltage, 1 magnetic encoder
    # (angle sensor), 2 temperature, 3 current, 5 load (scservo_sdk ERRBIT_VOLTAGE 1,
    # ERRBIT_ANGLE 2, ERRBIT_OVERHEAT 4, ERRBIT_OVERELE 8, ERRBIT_OVERLOAD 32 agree).
    "feetech_sts": {0: "voltage", 1: "encoder", 2: "overheating", 3: "overcurrent",
                    5: "overload"},
    # LewanSoul Bus Servo Communication Protocol, Table 3 (LED alarm codes): 1 over
    # temperature, 2 over voltage, 4 locked rotor. No packet carries them (the LED does).
    "lx": {0: "overheating", 1: "voltage", 2: "overload"},
    # ROBOTIS e-Manual XL-320, "Shutdown(18)" (whose bits Hardware Error Status(50) holds):
    # bit 0 Overload Error, bit 1 OverHeating Error, bit 2 Input Voltage Error.
    "dynamixel_xl320": {0: "overload", 1: "overheating", 2: "voltage"},
    # Feetech SCSCL memory table, "Servo Status": BIT0 voltage, BIT2 temperature, BIT5 load
    # (the SCS15 manual's "Current status byte": bit 0 over/under voltage, 2 over
    # temperature, 5 over load).
    "feetech_scs": {0: "voltage", 2: "overheating", 5: "overload"},
}

#: One step of the Return Delay Time register [s], per family.
RETURN_DELAY_UNIT_S: dict[str, float] = {
    # XL430-W250 "Return Delay Time(9)": 2 [us] per unit, 0..254 (initial 250 = 500 us).
    "dynamixel_x": 2e-6,
    # AX-12A "Return Delay Time(5)": 2 [us] per unit (initial 250 = 500 us).
    "dynamixel_p1": 2e-6,
    # STS memory table "Return delay time(7)": 2 us per unit (initial 0).
    "feetech_sts": 2e-6,
    # XL-320 "Return Delay Time(5)": the X series' include, 2 us per unit (initial 250).
    "dynamixel_xl320": 2e-6,
    # SCS15 manual "Return delay time(7)": 2 us per unit (initial 0), as the STS.
    "feetech_scs": 2e-6,
}


@dataclass(frozen=True)
class BusWatchdog:
    """A servo's communication watchdog register.

    register: its name in the family's control table; unit_s: one step [s]; steps: the
    values that arm it [inclusive]; off: the value that disarms it and clears a trip;
    tripped: the (signed) value it reads after a trip; min_firmware: first firmware with it.
    """

    register: str
    unit_s: float
    steps: tuple[int, int]
    off: int
    tripped: int
    min_firmware: int

    @property
    def range_s(self) -> tuple[float, float]:
        """Shortest and longest timeout it can arm [s]."""
        return self.steps[0] * self.unit_s, self.steps[1] * self.unit_s

    def accepts(self, value: int) -> bool:
        """Whether a host may write ``value``: ``off`` or an arming setting."""
        return value == self.off or self.steps[0] <= value <= self.steps[1]

    def deadline(self, setting: int, *, torque_on: bool, heard: float) -> float | None:
        """When it trips if nothing more is heard [s, same clock as ``heard``]; None when
        not armed (``setting`` off or tripped) or torque is off (it only watches then)."""
        if not torque_on or not self.steps[0] <= setting <= self.steps[1]:
            return None
        return heard + setting * self.unit_s


#: ROBOTIS e-Manual, XL430-W250, "Bus Watchdog(98)" (available from firmware v38): unit
#: 20 [ms]; 0 deactivates it and clears a Bus Watchdog Error; 1..127 activates it; -1 is
#: the Bus Watchdog Error status. It measures the interval between Instruction Packets
#: while Torque Enable(64) is 1; past the setting the servo stops, the register turns -1
#: and the Goal values (100, 102, 104, 116) become read-only: a write gets a Range Error
#: until 0 is written. Torque stays on (a trip sets no Hardware Error Status bit, so no
#: shutdown; the manual's example clears the error with 0 and the servo moves on the next
#: goal without a new Torque Enable). "All the Instruction Packet" may include packets
#: for other ids; the emulator takes the stricter reading (only packets addressed to the
#: servo count), so a host that forgets a servo sees it trip. The AX-12A / MX-28
#: Protocol 1.0 tables and the Feetech STS memory table have no such register (None).
BUS_WATCHDOG: dict[str, BusWatchdog | None] = {
    "dynamixel_x": BusWatchdog("bus_watchdog", 0.020, (1, 127), 0, -1, 38),
    "dynamixel_p1": None,
    "feetech_sts": None,
    "dynamixel_xl320": None,     # the XL-320 table has no Bus Watchdog
    "feetech_scs": None,         # nor the SCSCL table
}
