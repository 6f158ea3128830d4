"""`biped` command line: a thin dispatcher over ``robot.commands.<name>`` modules.

Each command module has ``add_parser(subparsers)`` and ``run(args) -> int``. Bad input gives
one clear line on stderr and exit code 2; nothing reaches the robot.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
from importlib.metadata import PackageNotFoundError, version

from robot.commands.common import one_line_errors
from robot.errors import BipedError, SafetyStop

# Order is the order of `biped --help`.
COMMANDS: tuple[str, ...] = (
    "walk",
    "play",
    "capture",
    "export",
    "import_",
    "curves",
    "scan",
    "torque",
    "pose",
    "emulate",
    "bench",
    "mjcf",
    "panel",
    "render",
    "plot",
    "setup_motors",
    "calibrate",
    "find_port",
    "monitor",
    "robustness",
    "tune",
    "identify",
)


def installed_version() -> str:
    """The installed distribution's version (importlib.metadata)."""
    try:
        return version("biped")
    except PackageNotFoundError:
        return "unknown (not installed; pip install .)"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="biped", description="Trigonometric-gait driver for hobby servo bipeds.")
    parser.add_argument("--version", action="version", version=f"biped {installed_version()}")
    parser.add_argument("--log-level", default="WARNING",
                        choices=["DEBUG", "INFO", "WARNING", "ERROR"], help="stderr log level")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        module = importlib.import_module(f"robot.commands.{name}")
        p = one_line_errors(module.add_parser(sub))
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:   # --help (0) or a refused option (2, one line on stderr)
        return e.code if isinstance(e.code, int) else 2
    logging.basicConfig(level=getattr(logging, args.log_level), stream=sys.stderr,
                        # the logger's name only when debugging: a user reads the message
                        format=("%(levelname)s %(name)s: %(message)s"
                                if args.log_level == "DEBUG" else "%(levelname)s: %(message)s"))
    try:
        return int(args._run(args) or 0)
    except SafetyStop as e:   # e.g. a run refused to start: a safety stop, exit 1
        print(f"biped {args.command}: safety stop: {e}", file=sys.stderr)
        return 1
    except BipedError as e:
        print(f"biped {args.command}: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0  # stdout closed early (e.g. piped into `head`)
    except KeyboardInterrupt:
        print(f"biped {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
