"""Fake serial adapters for `biped find-port` tests, served through pyserial itself.

The tests replace pyserial's backend, ``serial.tools.list_ports.comports``, with one that
returns pyserial's own ``ListPortInfo`` objects built from ``SerialPort`` samples: the
product's ``list_ports()`` (and so ``find-port``'s default lister) runs unchanged on them.
Each call returns the next listing of a script, and the last one again once it runs out
(the adapter stays as it was). In a subprocess: ``main([listings.json, *cli_args])``.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import pytest
from serial.tools import list_ports, list_ports_common

from robot.setup.serial_ports import SerialPort

Comports = Callable[..., list[list_ports_common.ListPortInfo]]


def port_info(port: SerialPort) -> list_ports_common.ListPortInfo:
    """What pyserial's backend reports for ``port``."""
    info = list_ports_common.ListPortInfo(port.device, skip_link_detection=True)
    info.description = port.description or "n/a"
    info.vid, info.pid = port.vid, port.pid
    info.serial_number, info.location = port.serial_number, port.location
    info.manufacturer, info.product = port.manufacturer, port.product
    return info


def scripted_comports(listings: Sequence[Sequence[SerialPort]]) -> Comports:
    """A ``comports`` replacement serving ``listings`` one call at a time."""
    if not listings:
        raise ValueError("scripted_comports needs at least one listing")
    calls = [0]

    def comports(include_links: bool = False) -> list[list_ports_common.ListPortInfo]:
        listing = listings[min(calls[0], len(listings) - 1)]
        calls[0] += 1
        return [port_info(p) for p in listing]
    return comports


def serve(monkeypatch: pytest.MonkeyPatch, listings: Sequence[Sequence[SerialPort]]) -> None:
    """Make pyserial list ``listings`` for the rest of the test."""
    monkeypatch.setattr(list_ports, "comports", scripted_comports(listings))


def write_listings(path: Path, listings: Sequence[Sequence[SerialPort]]) -> Path:
    path.write_text(json.dumps([[p.as_dict() for p in listing] for listing in listings]))
    return path


def main(argv: Sequence[str]) -> int:
    """``argv``: the listings file (``write_listings``), then biped's arguments."""
    data = json.loads(Path(argv[0]).read_text())
    setattr(list_ports, "comports", scripted_comports(  # noqa: B010 - a subprocess of its own
        [[SerialPort.from_dict(d) for d in listing] for listing in data]))
    import robot.cli as cli

    cli.COMMANDS = ("find_port",)
    return cli.main(list(argv[1:]))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
