"""Options shared by several commands, and the helpers that turn them into objects.

Option values are checked by argparse types (``rate_hz``, ``seconds``, ``output_file``, ...)
at parse time, before any file is loaded or port opened; with ``one_line_errors`` the
refusal is the single line ``biped <cmd>: error: argument --opt: expected ..., got ...``
and exit code 2.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn, TypeVar

from robot.bus.base import Bus
from robot.bus.factory import make_bus
from robot.config.bundled import DEFAULT_GAIT, DEFAULT_ROBOT_NAME, gait_names, robot_names, user_gaits_dir
from robot.config.checks import standard_bauds
from robot.config.gait_file import Gait, load_gait
from robot.config.params import GaitParams
from robot.config.robot import SERVO_ID, SPEED, RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.previs.figure_file import figure_format

T = TypeVar("T")


def one_line_errors(p: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Make ``p`` report a bad option as one line (no usage block) and exit 2, like every
    other refusal of the CLI. Returns ``p``."""
    def error(message: str) -> NoReturn:
        p.exit(2, f"{p.prog}: error: {message}\n")
    p.error = error  # type: ignore[method-assign]
    return p


def checked(option: str, parse: Callable[[str], T], text: str) -> T:
    """Apply the argparse type ``parse`` to ``text`` at run time: ConfigError
    ``<option>: <why>; expected ...`` instead of argparse's exit, so main() returns 2."""
    try:
        return parse(text)
    except argparse.ArgumentTypeError as e:
        raise ConfigError(f"{option}: {e}") from None


def positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return v


# ---------------------------------------------------------------- argparse types (ranges)


def bounded_float(lo: float, hi: float, unit: str, *, what: str = "a number",
                  lo_open: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite float in [lo, hi] (or (lo, hi] with ``lo_open``)."""
    span = f"{'(' if lo_open else '['}{lo:g}, {hi:g}] {unit}".rstrip()

    def parse(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            v = float("nan")
        if not ((lo < v if lo_open else lo <= v) and v <= hi):  # false for nan
            raise argparse.ArgumentTypeError(f"expected {what} in {span}, got {_short(text)}")
        return v
    parse.__name__ = what
    return parse


def bounded_int(lo: int, hi: int, unit: str = "", *,
                what: str = "an integer") -> Callable[[str], int]:
    """An argparse type: an integer in [lo, hi]."""
    span = f"[{lo}, {hi}] {unit}".rstrip()

    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:  # also Python's 4300-digit limit
            v = lo - 1
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"expected {what} in {span}, got {_short(text)}")
        return v
    parse.__name__ = what
    return parse


def _short(text: str) -> str:
    return repr(text) if len(text) <= 40 else repr(text[:40]) + f"... ({len(text)} chars)"


#: --rate: 1 Hz (slower is a slideshow) to 2000 Hz (a sync write + read of 12-18 servos
#: takes >= 0.5 ms even at 4 Mbps: docs, "wire-time limits").
rate_hz = bounded_float(1.0, 2000.0, "Hz", what="a rate")
#: --seconds: up to 1e6 s (11.6 days; an animatronics show runs all day, not for weeks).
seconds = bounded_float(0.0, 1e6, "s", what="a duration", lo_open=True)
#: --audio-offset: the show time the audio starts at, in the range of --seconds either way.
audio_offset = bounded_float(-1e6, 1e6, "s", what="a show time")
#: --speed: the joints' max_speed_rad_s range (robot.config.SPEED).
joint_speed = bounded_float(SPEED.lo, SPEED.hi, SPEED.unit, what="a joint speed")

#: Every standard baud rate of the supported servo families [bit/s].
#: The hardware bus kinds (robot.bus.factory.HARDWARE): Dynamixel 2.0, Dynamixel 1.0, Feetech.
HARDWARE_BUSES: tuple[str, ...] = ("dynamixel", "dynamixel1", "feetech", "lx")
BAUD_RATES: tuple[int, ...] = tuple(sorted({b for k in HARDWARE_BUSES
                                            for b in standard_bauds(k)}))


def baud_rate(text: str) -> int:
    """An argparse type: a standard servo baud rate (the bus family is checked by bus_from)."""
    try:
        v = int(text)
    except ValueError:
        v = -1
    if v not in BAUD_RATES:
        raise argparse.ArgumentTypeError(
            f"expected a standard servo baud rate ({', '.join(map(str, BAUD_RATES))}), "
            f"got {_short(text)}")
    return v


def id_list(text: str) -> list[int]:
    """An argparse type: '1-20' or '1,3,5-7' → sorted unique servo ids in SERVO_ID."""
    ids: set[int] = set()
    for part in text.split(","):
        a, dash, b = part.strip().partition("-")
        try:
            lo, hi = int(a), int(b if dash else a)
        except ValueError:
            lo, hi = 1, 0
        if not SERVO_ID.lo <= lo <= hi <= SERVO_ID.hi:  # before range(): no 1e9-id lists
            raise argparse.ArgumentTypeError(
                f"expected ids or ranges in [{SERVO_ID.lo:g}, {SERVO_ID.hi:g}] like 1-20 or "
                f"1,3,5-7, got {_short(part.strip())}")
        ids.update(range(lo, hi + 1))
    return sorted(ids)


def _writable_dir(d: Path) -> str | None:
    """Why files cannot be created in ``d``, or None if they can."""
    if not d.exists():
        return f"directory {d} does not exist"
    if not d.is_dir():
        return f"{d} is not a directory"
    if not os.access(d, os.W_OK | os.X_OK):
        return f"directory {d} is not writable"
    try:
        full = os.statvfs(d).f_bavail == 0
    except OSError:
        full = False                      # no statvfs there: the write will tell
    if full:
        return f"no space left on the device of directory {d}"
    return None


def output_file(text: str) -> str:
    """An argparse type: a file that can be written (its directory exists and is writable,
    it is not a directory, and if it exists it is writable). Checked before any work."""
    p = Path(text)
    why = (f"{text!r} is a directory" if p.is_dir() else
           _writable_dir(p.parent) or
           (f"{text} exists and is not writable" if p.exists() and not os.access(p, os.W_OK)
            else None))
    if why:
        raise argparse.ArgumentTypeError(f"{why}; expected a writable file path")
    return text


def plot_output(text: str) -> str:
    """An argparse type: an ``output_file`` whose suffix is a picture format a plot is
    written in (robot.previs.figure_file.FORMATS; none: PNG)."""
    output_file(text)
    try:
        figure_format(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    return text


@contextmanager
def writing(option: str, path: str | Path) -> Iterator[None]:
    """An OSError inside the block (the disk filled up while writing, ...) becomes one
    line naming ``option`` and ``path`` (ConfigError: exit 2)."""
    try:
        yield
    except OSError as e:
        raise ConfigError(f"{option} {path}: cannot write it: {e.strerror or e}") from e


def output_dir(text: str) -> str:
    """An argparse type: a directory that exists and is writable, or can be created (its
    nearest existing parent is a writable directory)."""
    p = Path(text)
    if p.exists():
        why = _writable_dir(p)
    else:
        parent = next(a for a in p.absolute().parents if a.exists())
        why = _writable_dir(parent)
    if why:
        raise argparse.ArgumentTypeError(f"{why}; expected a writable directory")
    return text


def input_file(text: str) -> str:
    """An argparse type: a regular file that can be read."""
    p = Path(text)
    why = (f"{text} does not exist" if not p.exists() else
           f"{text} is a directory" if p.is_dir() else
           f"{text} is not a regular file" if not p.is_file() else
           f"{text} is not readable" if not os.access(p, os.R_OK) else None)
    if why:
        raise argparse.ArgumentTypeError(f"{why}; expected a readable file")
    return text


def add_robot_args(p: argparse.ArgumentParser, *, gait: bool = True) -> None:
    p.add_argument("--robot", default=DEFAULT_ROBOT_NAME, metavar="NAME|PATH",
                   help=f"bundled robot ({', '.join(robot_names())}) or a robot TOML path "
                        "(default: %(default)s)")
    if gait:
        p.add_argument("--gait", default=DEFAULT_GAIT, metavar="NAME|PATH",
                       help=f"gait preset: bundled ({', '.join(gait_names())}), one saved in "
                            f"{user_gaits_dir()}, or a TOML path (default: %(default)s)")


def add_bus_args(p: argparse.ArgumentParser, *, default: str | None = None,
                 choices: tuple[str, ...] = ("sim", *HARDWARE_BUSES)) -> None:
    p.add_argument("--bus", default=default, choices=choices,
                   help="servo bus backend" + (f" (default: {default})" if default else ""))
    p.add_argument("--port", default=None, metavar="DEV", help="serial device (default: config)")
    p.add_argument("--baud", type=baud_rate, default=None,
                   help="baud rate (default: config); a standard rate of the servo family")


def robot_from(args: argparse.Namespace) -> RobotConfig:
    return load_robot(args.robot)


def bus_from(args: argparse.Namespace, robot: RobotConfig, *, kind: str | None = None,
             **options: Any) -> Bus:
    """A closed bus for ``--bus`` (or ``kind``, else the robot's) with ``--port``/``--baud``;
    ConfigError (nothing opened) if ``--baud`` is not a rate of that bus's servos."""
    kind = kind or args.bus or robot.bus.kind
    baud = getattr(args, "baud", None)
    if baud is not None and kind != "sim" and baud not in standard_bauds(kind):
        raise ConfigError(f"--baud {baud}: expected a {kind} baud rate (one of "
                          f"{', '.join(map(str, standard_bauds(kind)))})")
    return make_bus(kind, robot=robot, port=args.port, baud=baud, **options)


def gait_from(args: argparse.Namespace) -> Gait:
    return load_gait(args.gait)


def add_set_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override a gait parameter (repeatable), e.g. --set turn=0.2")


def parse_sets(items: list[str]) -> dict[str, float]:
    """``["turn=0.2", ...]`` → ``{"turn": 0.2}``; ConfigError naming a malformed item."""
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            if not sep:
                raise ValueError
            out[name.strip()] = float(value)
        except ValueError:
            raise ConfigError(f"--set {item!r}: expected NAME=NUMBER, e.g. turn=0.2") from None
    return out


def params_from(args: argparse.Namespace, robot: RobotConfig | None = None
                ) -> tuple[Gait, GaitParams]:
    """The ``--gait`` preset and its parameters (with ``robot``'s ``[balance]`` gains for
    those the preset does not name) with every ``--set`` applied (validated)."""
    gait = gait_from(args)
    base = gait.params if robot is None else gait.for_robot(robot)
    return gait, base.replace(parse_sets(args.set), where="--set")
