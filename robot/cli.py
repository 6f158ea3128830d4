"""`biped` command line: a thin dispatcher over ``robot.commands.<name>`` modules.

Each command module has ``add_parser(subparsers)`` and ``run(args) -> int``. Bad input gives
one clear line on stderr and exit code 2; nothing reaches the robot. A bus error (a servo
missing or silent, the port failing) or a safety stop is one line and exit code 1.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import signal
import sys
from collections.abc import Sequence
from importlib.metadata import PackageNotFoundError, version

from robot.commands.common import one_line_errors
from robot.errors import BipedError, BusError, SafetyStop
from robot.run.signals import Interrupted, SignalLatch

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
    "robots",
    "setup_motors",
    "calibrate",
    "find_port",
    "monitor",
    "robustness",
    "tune",
    "identify",
    "sim_gap",
)


def installed_version() -> str:
    """The installed distribution's version (importlib.metadata)."""
    try:
        return version("biped")
    except PackageNotFoundError:
        return "unknown (not installed; pip install .)"


def command_of(argv: Sequence[str]) -> str | None:
    """The command module ``argv`` names (``setup-motors``: ``setup_motors``), or None: no
    command, an option first (``--help``, ``--version``) or a name no command has, which
    the whole parser answers."""
    i = 0
    while i < len(argv) and argv[i] == "--log-level":
        i += 2
    if i >= len(argv) or argv[i].startswith("-"):
        return None
    name = argv[i].replace("-", "_")
    return next((c for c in (name, f"{name}_") if c in COMMANDS), None)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command, or of ``only`` (a module name in COMMANDS): a command
    then imports what it needs and not what the others do (mujoco, the glTF writer, ...):
    it starts sooner, on a Raspberry Pi by a second or more."""
    parser = argparse.ArgumentParser(
        prog="biped", description="Trigonometric-gait driver for hobby servo bipeds.")
    parser.add_argument("--version", action="version", version=f"biped {installed_version()}")
    parser.add_argument("--log-level", default="WARNING",
                        choices=["DEBUG", "INFO", "WARNING", "ERROR"], help="stderr log level")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS if only is None else (only,):
        module = importlib.import_module(f"robot.commands.{name}")
        p = one_line_errors(module.add_parser(sub))
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one ``biped`` command; its exit code. SIGINT/SIGTERM are handled from here on
    (robot.run.signals): no command is killed by them. ``argv`` None: this process is the
    command (the console script, ``python -m robot.cli``): it exits here with the code,
    the handlers in place to the end; otherwise (in-process callers) the old handlers
    come back and the code is returned."""
    latch = SignalLatch()
    restore = latch.install()
    try:
        code = _main(argv)
    finally:
        if argv is not None:
            restore()
    if argv is None:
        latch.end(code)
    return code


def _main(argv: list[str] | None) -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        parser = build_parser(command_of(sys.argv[1:] if argv is None else argv))
        args = parser.parse_args(argv)
    except SystemExit as e:   # --help (0) or a refused option (2, one line on stderr)
        return e.code if isinstance(e.code, int) else 2
    except KeyboardInterrupt as e:
        return interrupted("", e)
    logging.basicConfig(level=getattr(logging, args.log_level), stream=sys.stderr,
                        # the logger's name only when debugging: a user reads the message
                        format=("%(levelname)s %(name)s: %(message)s"
                                if args.log_level == "DEBUG" else "%(levelname)s: %(message)s"))
    try:
        return int(args._run(args) or 0)
    except SafetyStop as e:   # e.g. a run refused to start: a safety stop, exit 1
        print(f"biped {args.command}: safety stop: {e}", file=sys.stderr)
        return 1
    except BusError as e:     # a servo missing or silent, the port failed: hardware, exit 1
        print(f"biped {args.command}: bus error: {e}", file=sys.stderr)
        return 1
    except BipedError as e:
        print(f"biped {args.command}: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0  # stdout closed early (e.g. piped into `head`)
    except OSError as e:      # a file no command check caught (a full disk, ...): one line
        where = f"{e.filename}: " if e.filename else ""
        print(f"biped {args.command}: error: {where}{e.strerror or e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        return interrupted(f" {args.command}", e)


def interrupted(command: str, e: KeyboardInterrupt) -> int:
    """Say so; 128 + the signal's number (130 for SIGINT, 143 for SIGTERM)."""
    signum = e.signum if isinstance(e, Interrupted) else signal.SIGINT
    print(f"biped{command}: interrupted ({signal.Signals(signum).name})", file=sys.stderr)
    return 128 + signum


if __name__ == "__main__":
    sys.exit(main())
