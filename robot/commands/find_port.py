"""`biped find-port`: list the serial adapters, and find the robot's by unplugging it.

Without options: list the adapters, ask you to unplug the robot's USB adapter (Enter), list
again (the one that went away is the robot's), ask you to plug it back in (Enter) and print
the name it came back under, which is the one to pass as ``--port``. ``--list`` only lists.
``--json``: one JSON value on stdout (the list, or the found port); prompts go to stderr.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

from robot.commands.common import one_line_errors
from robot.setup.serial_ports import (
    PortLister,
    PortSearchError,
    SerialPort,
    added_port,
    list_ports,
    removed_port,
)

#: How long to keep re-listing after Enter while the OS catches up with a (un)plug [s].
SETTLE_S = 2.0
BY_ID = Path("/dev/serial/by-id")


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("find-port", help="list serial adapters; find the robot's by "
                              "unplugging it", description=__doc__)
    p.add_argument("--list", action="store_true", help="only list the adapters")
    p.add_argument("--json", action="store_true",
                   help="print one JSON value on stdout (prompts go to stderr)")
    return one_line_errors(p)


def stable_path(device: str, by_id: Path = BY_ID) -> str | None:
    """The /dev/serial/by-id link to ``device`` (same name after a replug), if any."""
    try:
        links = sorted(by_id.iterdir())
    except OSError:
        return None
    target = Path(device).resolve()
    return next((str(link) for link in links if link.resolve() == target), None)


def print_ports(ports: list[SerialPort], out: TextIO) -> None:
    if not ports:
        print("no serial adapters found", file=out)
        return
    print(f"{len(ports)} serial adapter(s):", file=out)
    print(f"  {'device':<16} {'VID:PID':<10} {'vendor / product':<36} {'serial':<14} "
          "description", file=out)
    for p in ports:
        what = " / ".join(x for x in (p.vendor, p.product) if x) or "-"
        print(f"  {p.device:<16} {p.vid_pid or '-':<10} {what:<36} "
              f"{p.serial_number or '-':<14} {p.description or '-'}", file=out)


def _settled(lister: PortLister, before: list[SerialPort],
             differs: Callable[[list[SerialPort]], bool], settle_s: float) -> list[SerialPort]:
    """List again until the listing ``differs`` or ``settle_s`` has passed."""
    end = time.monotonic() + settle_s
    while True:
        now = lister()
        if differs(now) or time.monotonic() >= end:
            return now
        time.sleep(0.1)


def run(args: argparse.Namespace, *, lister: PortLister | None = None,
        read_line: Callable[[], str] | None = None, settle_s: float = SETTLE_S) -> int:
    """``lister`` (default: pyserial's ``list_ports``) lists the ports; ``read_line``
    (default: stdin) waits for Enter and returns '' at end of input."""
    lister = lister or list_ports
    read_line = read_line or sys.stdin.readline
    ports = lister()
    if args.list:
        if args.json:
            print(json.dumps([p.as_dict() for p in ports]))
        else:
            print_ports(ports, sys.stdout)
        return 0
    talk = sys.stderr if args.json else sys.stdout
    print_ports(ports, talk)
    if not ports:
        raise PortSearchError("no serial adapters found; plug in the robot's USB adapter "
                              "(and power), then run biped find-port again")

    def ask(prompt: str) -> None:
        print(prompt, file=talk, flush=True)
        if not read_line():
            raise PortSearchError("no answer on stdin (end of input); run biped find-port "
                                  "in a terminal")

    ask("Unplug the robot's USB adapter from the computer, then press Enter.")
    unplugged = _settled(lister, ports, lambda now: len(now) < len(ports), settle_s)
    gone = removed_port(ports, unplugged)
    ask(f"{gone.device} went away. Plug it back in, then press Enter.")
    replugged = _settled(lister, unplugged, lambda now: len(now) > len(unplugged), settle_s)
    port = added_port(unplugged, replugged)
    stable = stable_path(port.device)
    if args.json:
        print(json.dumps({**port.as_dict(), "stable_path": stable}))
        return 0
    again = "" if port.device == gone.device else f" (it was {gone.device} before)"
    print(f"robot's adapter: {port.summary()}{again}; use --port {stable or port.device}")
    return 0
