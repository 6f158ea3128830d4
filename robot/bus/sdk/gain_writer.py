"""The robot file's gains onto the servos, before torque on, read back and verified.

``apply(bus, ids)`` resolves each servo's gains (``RobotConfig.gains``: factory <-
``[bus.gains]`` <- ``[joints.<name>.gains]``), writes them and reads them back:

- RAM gains (Dynamixel X, AX, MX): one sync write per register, every time (RAM comes back
  at the factory value at every power-on).
- EEPROM gains (Feetech STS coefficients): read first, and written only where they differ,
  with the EEPROM unlocked (Lock(55) = 0) and locked again (1) around the write, as the
  Feetech memory table says; each change is logged. EEPROM wears, so a robot whose file
  does not change writes nothing on the next run.
- Then every gain of every servo is read back; a value that differs is a BusError naming
  the servo, its joint, the register, the value wanted and the value read.

``read(bus, sid, gain_set)`` reads one servo's gains (for scan and monitor).
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping

from robot.bus.sdk.registers import SdkRegisters
from robot.bus.tables import EEPROM_LOCK, GAIN_REGISTERS, Register
from robot.errors import BusError
from robot.servo.gains import GAIN_SETS

log = logging.getLogger(__name__)


def read(bus: SdkRegisters, sid: int, gain_set: str) -> dict[str, int]:
    """Servo ``sid``'s gain registers of ``gain_set`` [register values], in one read."""
    regs = GAIN_REGISTERS[gain_set]
    start = min(r.address for r in regs.values())
    end = max(r.address + r.size for r in regs.values())
    block = bus.read_bytes(sid, start, end - start, "gains")
    return {name: int.from_bytes(block[r.address - start:r.address - start + r.size], "little")
            for name, r in regs.items()}


def apply(bus: SdkRegisters, ids: Iterable[int]) -> None:
    """Write and verify the robot file's gains on ``ids`` (ids without a joint in the robot
    config are left alone). Raises BusError on a failed transaction or a read-back mismatch."""
    robot = bus.robot
    if robot is None:
        return
    plan: dict[str, dict[int, Mapping[str, int]]] = {}
    for sid in sorted(set(ids)):
        joint = robot.joint_by_id(sid)
        if joint is not None:
            plan.setdefault(robot.servo(joint).gain_set, {})[sid] = robot.gains(joint)
    for gain_set, wanted in plan.items():
        gains = GAIN_SETS[gain_set]
        regs = GAIN_REGISTERS[gain_set]
        for name, g in gains.gains.items():
            if g.memory == "ram":
                bus.sync_write(regs[name], {sid: w[name] for sid, w in wanted.items()}, name)
        if gains.eeprom:
            for sid, w in wanted.items():
                present = read(bus, sid, gain_set)
                changed = {n: w[n] for n in gains.eeprom if present[n] != w[n]}
                if changed:
                    _write_eeprom(bus, sid, regs, changed)
                    log.info("%s: EEPROM gains changed (%s): written once, not on every run "
                             "(EEPROM wears)", bus.who(sid),
                             ", ".join(f"{n} {present[n]} -> {v}" for n, v in changed.items()))
        for sid, w in wanted.items():
            _verify(bus, sid, gain_set, w)
        log.debug("gains %s verified on ids %s", gain_set, sorted(wanted))


def _write_eeprom(bus: SdkRegisters, sid: int, regs: Mapping[str, Register],
                  values: Mapping[str, int]) -> None:
    lock = EEPROM_LOCK[bus.family]
    if lock is not None:
        bus.write_register(sid, lock[0], lock[1])
    try:
        for name, v in values.items():
            bus.write_at(sid, regs[name], v, name)
    finally:
        if lock is not None:
            bus.write_register(sid, lock[0], lock[2])


def _verify(bus: SdkRegisters, sid: int, gain_set: str, wanted: Mapping[str, int]) -> None:
    got = read(bus, sid, gain_set)
    wrong = [n for n in wanted if got[n] != wanted[n]]
    if not wrong:
        return
    regs = GAIN_REGISTERS[gain_set]
    detail = "; ".join(f"{n} (address {regs[n].address}) wanted {wanted[n]}, read {got[n]}"
                       for n in wrong)
    joint = bus.robot.joint_by_id(sid) if bus.robot else None
    where = (f"[bus.gains] / [joints.{joint.name}.gains] in {bus.robot.source}"
             if joint is not None and bus.robot is not None else "the robot file")
    raise BusError(f"{bus.kind} {bus.port_name} @ {bus.baud}: {bus.who(sid)}: gains read back "
                   f"wrong after writing: {detail}; torque stays off. Is the servo the model "
                   f"the robot file names (`biped scan`)? Check {where}")
