"""Options shared by several commands, and the helpers that turn them into objects."""

from __future__ import annotations

import argparse

from robot.config import DEFAULT_GAIT, DEFAULT_ROBOT, Gait, RobotConfig, load_gait, load_robot
from robot.errors import ConfigError
from robot.params import GaitParams


def positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}") from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return v


def positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return v


def add_robot_args(p: argparse.ArgumentParser, *, gait: bool = True) -> None:
    p.add_argument("--robot", default=str(DEFAULT_ROBOT), metavar="PATH",
                   help="robot TOML (default: %(default)s)")
    if gait:
        p.add_argument("--gait", default=DEFAULT_GAIT, metavar="NAME|PATH",
                       help="gait preset name or TOML path (default: %(default)s)")


def add_bus_args(p: argparse.ArgumentParser, *, default: str | None = None,
                 choices: tuple[str, ...] = ("sim", "dynamixel", "feetech")) -> None:
    p.add_argument("--bus", default=default, choices=choices,
                   help="servo bus backend" + (f" (default: {default})" if default else ""))
    p.add_argument("--port", default=None, metavar="DEV", help="serial device (default: config)")
    p.add_argument("--baud", type=positive_int, default=None, help="baud rate (default: config)")


def robot_from(args: argparse.Namespace) -> RobotConfig:
    return load_robot(args.robot)


def gait_from(args: argparse.Namespace) -> Gait:
    return load_gait(args.gait)


def parse_ids(text: str) -> list[int]:
    """'1-20' or '1,3,5-7' → ids; raises ConfigError naming the bad part."""
    ids: list[int] = []
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                a, b = part.split("-", 1)
                lo, hi = int(a), int(b)
                if lo > hi:
                    raise ValueError
                ids.extend(range(lo, hi + 1))
            else:
                ids.append(int(part))
        except ValueError:
            raise ConfigError(f"--ids: cannot read {part!r}; expected e.g. 1-20 or 1,3,5-7") from None
    bad = [i for i in ids if not 0 <= i <= 252]
    if bad:
        raise ConfigError(f"--ids: id {bad[0]} is outside [0, 252]")
    return sorted(set(ids))


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


def params_from(args: argparse.Namespace) -> tuple[Gait, GaitParams]:
    """The ``--gait`` preset and its parameters with every ``--set`` applied (validated)."""
    gait = gait_from(args)
    return gait, gait.params.replace(parse_sets(args.set), where="--set")
