"""Connection health checks run when a vendor bus opens, and the fixes they offer.

``check(bus)`` returns warnings (also logged) for: a USB latency timer above 1 ms, servos
with a non-zero return delay, configured servos that do not answer. If *no* configured
servo answers, it probes the other standard baud rates and raises BusError naming the one
that answers. Each warning says how to fix it.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot.bus.tables import EEPROM_LOCK, RETURN_DELAY_UNIT_S
from robot.errors import BusError
from robot.servo.models import BAUD_CODES

if TYPE_CHECKING:
    from robot.bus.sdk.registers import SdkRegisters

log = logging.getLogger(__name__)

SYSFS_USB_SERIAL = Path("/sys/bus/usb-serial/devices")
#: How many ids to ping per baud rate while probing (each silent ping costs a timeout).
PROBE_IDS = 3


def try_low_latency(ser: Any) -> bool:
    """Ask the kernel for low-latency mode (FTDI: latency timer 1 ms); False if refused."""
    try:
        ser.set_low_latency_mode(True)
    except (OSError, ValueError, AttributeError, NotImplementedError) as e:
        log.debug("low-latency mode not available on %s: %s", getattr(ser, "port", "?"), e)
        return False
    return True


def latency_timer_path(port: str, *, sysfs: Path = SYSFS_USB_SERIAL) -> Path | None:
    """The sysfs latency_timer file of a USB-serial ``port`` (symlinks resolved), if any."""
    path = sysfs / Path(os.path.realpath(port)).name / "latency_timer"
    return path if path.exists() else None


def latency_warning(port: str, *, sysfs: Path = SYSFS_USB_SERIAL) -> str | None:
    """A warning when the USB latency timer of ``port`` is above 1 ms."""
    path = latency_timer_path(port, sysfs=sysfs)
    if path is None:
        return None
    try:
        ms = int(path.read_text().strip())
    except (OSError, ValueError) as e:
        log.debug("cannot read %s: %s", path, e)
        return None
    if ms <= 1:
        return None
    return (f"USB latency timer of {port} is {ms} ms: every reply waits up to {ms} ms in the "
            f"adapter. Fix: `echo 1 | sudo tee {path}` (or a udev rule setting "
            "ATTR{latency_timer}=\"1\")")


def return_delay_warning(bus: SdkRegisters, sid: int, raw: int) -> str:
    us = raw * RETURN_DELAY_UNIT_S[bus.family] * 1e6
    reg = bus.table["return_delay_time"]
    return (f"{bus.who(sid)} has a return delay of {us:.0f} µs (return_delay_time = {raw}): "
            f"every read waits that long per servo. Fix: `biped scan --bus {bus.kind} --port "
            f"{bus.port_name} --baud {bus.baud} --fix-return-delay` (writes return_delay_time "
            f"= 0 at address {reg.address}, torque off)")


def probe_baud(bus: SdkRegisters, ids: Sequence[int]) -> tuple[int, list[int]] | None:
    """The first other standard baud rate at which one of ``ids[:PROBE_IDS]`` answers, with
    the ids that did; the bus is left at its original rate."""
    original = bus.baud
    try:
        for rate in sorted(BAUD_CODES[bus.family].values(), reverse=True):
            if rate == original:
                continue
            try:
                bus.set_baud(rate)
            except BusError:
                continue  # a rate the SDK cannot set
            found = [sid for sid in ids[:PROBE_IDS] if bus.ping(sid) is not None]
            if found:
                return rate, found
        return None
    finally:
        bus.set_baud(original)


def wrong_baud_error(bus: SdkRegisters, ids: Sequence[int]) -> BusError:
    """The error for "nothing answers": names the rate that does, if one does."""
    listed = ", ".join(bus.who(i) for i in ids[:4]) + (" ..." if len(ids) > 4 else "")
    probe = probe_baud(bus, ids)
    head = f"no servo answers on {bus.port_name} at {bus.baud} baud (tried {listed})"
    if probe is None:
        return BusError(f"{head}, nor at any other standard rate; check power (LEDs flash at "
                        f"power-up), the data cable and the adapter, then `biped scan --bus "
                        f"{bus.kind} --port {bus.port_name}`")
    rate, found = probe
    verb = "answers" if len(found) == 1 else "answer"
    return BusError(f"{head}, but {', '.join(bus.who(i) for i in found)} {verb} at {rate} "
                    f"baud: is the baud rate right? use --baud {rate} (or bus.baud = {rate} in "
                    "the robot config), or set every servo to the configured rate")


def check(bus: SdkRegisters) -> list[str]:
    """All health checks for an open bus; returns (and logs) warnings, raises on wrong baud."""
    warnings: list[str] = []
    latency = latency_warning(bus.port_name)
    if latency:
        warnings.append(latency)
    if bus.robot is not None:
        ids = list(bus.robot.ids)
        present = [sid for sid in ids if bus.ping(sid) is not None]
        if not present:
            raise wrong_baud_error(bus, ids)
        # A second chance: one late reply should not read as a missing servo.
        present += [sid for sid in ids if sid not in present and bus.ping(sid) is not None]
        missing = [sid for sid in ids if sid not in present]
        if missing:
            warnings.append(f"configured servos not answering: "
                            f"{', '.join(bus.who(i) for i in missing)}; check their power and "
                            "wiring (and ids with `biped scan`)")
        for sid in present:
            raw = bus.read_register(sid, "return_delay_time")
            bus.return_delay_s = max(bus.return_delay_s, raw * RETURN_DELAY_UNIT_S[bus.family])
            if raw:
                warnings.append(return_delay_warning(bus, sid, raw))
    for w in warnings:
        log.warning("%s", w)
    return warnings


def fix_return_delay(bus: SdkRegisters, ids: Iterable[int]) -> list[int]:
    """Set return_delay_time to 0 (EEPROM, so torque off first) where it is not; returns the
    ids changed. Feetech EEPROM is unlocked for the write and locked again. Only Feetech:
    an AX-12A's Lock (47) is another thing, "1 locks EEPROM until power-off" (e-Manual), so
    it is never written; Dynamixel needs torque off for EEPROM, nothing more."""
    changed: list[int] = []
    for sid in ids:
        if bus.read_register(sid, "return_delay_time") == 0:
            continue
        bus.set_torque([sid], enabled=False)
        lock = EEPROM_LOCK[bus.family]
        if lock:
            bus.write_register(sid, lock[0], lock[1])
        bus.write_register(sid, "return_delay_time", 0)
        if lock:
            bus.write_register(sid, lock[0], lock[2])
        changed.append(sid)
    return changed
