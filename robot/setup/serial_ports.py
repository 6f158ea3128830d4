"""Serial adapters on this machine, and which one went away (pure comparison logic).

``list_ports()`` asks pyserial (``serial.tools.list_ports.comports``); everything else is
pure and works on ``SerialPort`` lists.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

from robot.errors import BipedError

#: USB vendor ids of common USB-serial chips, for adapters that do not name their maker.
VENDORS: dict[int, str] = {
    0x0403: "FTDI",                  # FT232R/FT232H (ROBOTIS U2D2 is an FT232H)
    0x1A86: "QinHeng Electronics",   # CH340/CH343 (many Feetech/Waveshare boards)
    0x10C4: "Silicon Labs",          # CP210x
    0x067B: "Prolific",              # PL2303
    0x2341: "Arduino",
    0x16C0: "Van Ooijen Technische Informatica",  # Teensy, OpenCM
    0x0483: "STMicroelectronics",
}

PortLister = Callable[[], list["SerialPort"]]


class PortSearchError(BipedError):
    """The unplug/replug comparison did not single out one adapter."""


@dataclass(frozen=True)
class SerialPort:
    """One serial device. vid/pid: USB vendor/product id (None when not USB)."""

    device: str
    description: str = ""
    vid: int | None = None
    pid: int | None = None
    serial_number: str | None = None
    manufacturer: str | None = None
    product: str | None = None
    location: str | None = None

    @property
    def vid_pid(self) -> str | None:
        """``"0403:6014"`` or None."""
        if self.vid is None or self.pid is None:
            return None
        return f"{self.vid:04x}:{self.pid:04x}"

    @property
    def vendor(self) -> str | None:
        """The maker: as the adapter reports it, else from the vendor id."""
        return self.manufacturer or (VENDORS.get(self.vid) if self.vid is not None else None)

    def summary(self) -> str:
        """``/dev/ttyUSB0 (FTDI FT232R USB UART, 0403:6001, serial A50285BI)``."""
        what = " ".join(x for x in (self.vendor, self.product) if x) or (
            self.description if self.description not in ("", "n/a") else "")
        parts = [p for p in (what, self.vid_pid,
                             f"serial {self.serial_number}" if self.serial_number else None) if p]
        return f"{self.device} ({', '.join(parts)})" if parts else self.device

    def as_dict(self) -> dict[str, Any]:
        return {**asdict(self), "vid_pid": self.vid_pid, "vendor": self.vendor}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> SerialPort:
        """The inverse of ``as_dict`` (extra keys ignored); BipedError without a device."""
        if not isinstance(d, dict) or not isinstance(d.get("device"), str):
            raise BipedError(f"a serial port entry needs a \"device\" string, got {d!r}")
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in names})


def list_ports() -> list[SerialPort]:
    """The serial devices pyserial finds, sorted by device name."""
    from serial.tools import list_ports as lp

    return sorted((SerialPort(device=p.device, description=p.description or "",
                              vid=p.vid, pid=p.pid, serial_number=p.serial_number,
                              manufacturer=p.manufacturer, product=p.product,
                              location=p.location)
                   for p in lp.comports()), key=lambda p: p.device)


def _names(ports: Sequence[SerialPort]) -> str:
    return ", ".join(p.device for p in ports)


def removed_port(before: Sequence[SerialPort], after: Sequence[SerialPort]) -> SerialPort:
    """The one port in ``before`` that is not in ``after`` (compared by device name);
    PortSearchError (one line) when none or several went away."""
    now = {p.device for p in after}
    gone = [p for p in before if p.device not in now]
    if len(gone) == 1:
        return gone[0]
    if not gone:
        raise PortSearchError(
            f"no serial port went away ({len(before)} before, {len(after)} after: "
            f"{_names(after) or 'none'}); unplug the robot's USB adapter from the computer, "
            "then press Enter")
    raise PortSearchError(f"{len(gone)} serial ports went away ({_names(gone)}); unplug "
                          "only the robot's adapter and try again")


def added_port(before: Sequence[SerialPort], after: Sequence[SerialPort]) -> SerialPort:
    """The one port in ``after`` that is not in ``before``; PortSearchError otherwise."""
    was = {p.device for p in before}
    new = [p for p in after if p.device not in was]
    if len(new) == 1:
        return new[0]
    if not new:
        raise PortSearchError("no serial port came back; plug the robot's USB adapter in "
                              "again, wait a second, then press Enter")
    raise PortSearchError(f"{len(new)} serial ports appeared ({_names(new)}); plug in only "
                          "the robot's adapter and try again")
