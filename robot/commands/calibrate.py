"""`biped calibrate`: measure zero_ticks, sign and (optionally) limits by hand; write a new
robot TOML.

Torque stays off the whole time and no goal is ever written: the robot does not move by
itself. Step 1: hold the robot in its zero pose (every joint at 0 rad: standing straight,
feet flat and parallel, arms hanging at the sides) and zero_ticks are read from the present
positions. Step 2: move each joint by hand the way the prompt says; the direction of the
tick change confirms or flips its sign. Step 3 (``--limits``): move each joint to both ends
of its free range; min_rad/max_rad are recorded inside the servo's own limits. A joint that
does not move is asked again at once. Limits the servo cannot reach from its new zero are
narrowed (said per joint). The output keeps the input's comments and layout and is
validated before it is written; a bundled robot's name becomes the output's file name.
Exit 1 when a joint's sign or limits were asked for and not measured (the measured joints
are written all the same).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from robot.bus.base import Bus
from robot.commands.calibrate_report import report
from robot.commands.common import (
    HARDWARE_BUSES,
    add_bus_args,
    add_robot_args,
    bus_from,
    one_line_errors,
    output_file,
    robot_from,
)
from robot.config.bundled import robot_names
from robot.config.robot import JointConfig, RobotConfig
from robot.config.toml_edit import same_path, write_validated
from robot.errors import ConfigError
from robot.run.session import bus_session
from robot.setup.calibration import (
    MOVE_THRESHOLD_RAD,
    detect_sign,
    direction_words,
    limits_from_ends,
    probe_direction,
    wrapped_delta,
    zero_ticks,
)
from robot.setup.calibration_result import settle
from robot.setup.motor_setup import answered

Ask = Callable[[str], str]
#: Prompts per joint in step 2 before its sign is left unmeasured (kept as it was).
SIGN_TRIES = 3
#: Tries per joint in step 3 before its limits are left unmeasured (kept as they were).
LIMIT_TRIES = 3
#: The servo's own position-limit registers, per bus kind.
LIMIT_REGISTERS = {"dynamixel": ("min_position_limit", "max_position_limit"),
                   "dynamixel1": ("cw_angle_limit", "ccw_angle_limit"),
                   "feetech": ("min_angle_limit", "max_angle_limit"),
                   "lx": ("min_angle_limit", "max_angle_limit")}


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("calibrate", help="measure zero, sign and limits by hand "
                              "(torque off) into a new robot TOML", description=__doc__)
    add_robot_args(p, gait=False)
    add_bus_args(p, choices=HARDWARE_BUSES)
    p.add_argument("--out", required=True, type=output_file, metavar="NEW.toml",
                   help="robot TOML to write (a copy of --robot with the measured values)")
    p.add_argument("--overwrite", action="store_true", help="allow --out to be the --robot file")
    p.add_argument("--zero", action="store_true", help="step 1 only (zero_ticks)")
    p.add_argument("--limits", action="store_true", help="also step 3: record min/max_rad")
    p.add_argument("--yes", action="store_true",
                   help="no prompt: the robot is already held in its zero pose (needs --zero)")
    return one_line_errors(p)


def _position(bus: Bus, joint: JointConfig) -> int:
    return bus.read_positions([joint.servo_id])[joint.servo_id]


def _signs(bus: Bus, robot: RobotConfig, ask: Ask) -> dict[str, int]:
    """Step 2: ``{joint: sign}`` from one hand move per joint, for the joints that moved."""
    res, per_rad = robot.bus.servo.resolution, robot.bus.servo.ticks_per_rad
    out: dict[str, int] = {}
    print(f"step 2: move each joint by hand, about 20-30 degrees, the way it says "
          f"(a move under {MOVE_THRESHOLD_RAD} rad does not count)")
    for j in robot.joints:
        direction = probe_direction(robot, j.name)
        for _ in range(SIGN_TRIES):
            before = _position(bus, j)
            ask(f"{j.name} (id {j.servo_id}): move it so that {direction_words(j.name, direction)}"
                f" ({'+' if direction > 0 else '-'} direction), hold it and press Enter ")
            reading = detect_sign(before, _position(bus, j), direction=direction,
                                  resolution=res, ticks_per_rad=per_rad)
            if reading.sign is not None:
                out[j.name] = reading.sign
                flip = " (flipped)" if reading.sign != j.sign else ""
                print(f"  {j.name}: {reading.delta:+d} ticks -> sign {reading.sign:+d}{flip}")
                break
            print(f"  {j.name}: moved only {reading.delta:+d} ticks; again, further")
        else:
            print(f"  {j.name}: no move seen in {SIGN_TRIES} tries; sign NOT measured (the "
                  f"file keeps {j.sign:+d})")
        ask(f"put {j.name} back to its zero pose and press Enter ")
    return out


def _servo_limits(bus: Bus, j: JointConfig, kind: str) -> tuple[int, int] | None:
    """The joint's servo position-limit registers (lo, hi) [ticks]; None where they span
    nothing (lo >= hi) or the bus has no registers."""
    read = getattr(bus, "read_register", None)
    if read is None:
        return None
    lo, hi = (int(read(j.servo_id, r)) for r in LIMIT_REGISTERS[kind])
    return (lo, hi) if lo < hi else None


def _limits(bus: Bus, robot: RobotConfig, zeros: dict[str, int], signs: dict[str, int],
            kind: str, ask: Ask) -> dict[str, tuple[float, float]]:
    """Step 3: ``{joint: (min_rad, max_rad)}`` from the two ends of each joint's free range,
    for the joints whose ends were at least MOVE_THRESHOLD_RAD apart (asked again at once,
    LIMIT_TRIES times, when they were not)."""
    out: dict[str, tuple[float, float]] = {}
    print("step 3: move each joint by hand to both ends of its free range (where it touches "
          "the frame or a cable pulls), gently")
    for j in robot.joints:
        servo = robot.servo(j)
        res, per_rad = servo.resolution, servo.ticks_per_rad
        sign, servo_limits = signs.get(j.name, j.sign), _servo_limits(bus, j, kind)
        for _ in range(LIMIT_TRIES):
            ends = []
            for which in ("one end", "the other end"):
                ask(f"{j.name} (id {j.servo_id}): hold it at {which} of its free range and "
                    "press Enter ")
                ends.append(_position(bus, j))
            span = abs(wrapped_delta(ends[0], ends[1], res)) / per_rad
            lo, hi = limits_from_ends(ends[0], ends[1], zero=zeros[j.name], sign=sign,
                                      resolution=res, servo_limits=servo_limits,
                                      ticks_per_rad=per_rad)
            if span >= MOVE_THRESHOLD_RAD and lo < hi:
                out[j.name] = (lo, hi)
                print(f"  {j.name}: [{lo:+.3f}, {hi:+.3f}] rad")
                break
            print(f"  {j.name}: the two ends are only {span:.2f} rad apart (at least "
                  f"{MOVE_THRESHOLD_RAD} rad); again, to the very ends")
        else:
            print(f"  {j.name}: limits NOT measured in {LIMIT_TRIES} tries (the file keeps "
                  f"[{j.min_rad:+.3f}, {j.max_rad:+.3f}])")
        ask(f"put {j.name} back to its zero pose and press Enter ")
    return out


def run(args: argparse.Namespace, *, ask: Ask = input) -> int:
    robot = robot_from(args)
    source, out = Path(robot.source), Path(args.out)   # --robot may be a bundled name
    if same_path(source, out) and not args.overwrite:
        raise ConfigError(f"--out {args.out}: is the --robot file ({source}); write a new "
                          "file and compare, or add --overwrite")
    ask = answered(ask, "nothing was written")
    if args.yes and not args.zero:
        raise ConfigError("--yes needs --zero: steps 2 and 3 need a human moving the joints")
    if args.zero and args.limits:
        raise ConfigError("--zero runs step 1 alone; drop --limits or --zero")
    kind = args.bus or robot.bus.kind
    bus = bus_from(args, robot)
    with bus_session(bus, torque_off=True):
        bus.set_torque(robot.ids, enabled=False)
        print(f"torque OFF on {len(robot.ids)} servos: the robot is limp and will not move "
              "by itself; support it")
        if not args.yes:
            ask("step 1: hold the robot in its zero pose (standing straight, feet flat and "
                "parallel, arms hanging at the sides) and press Enter ")
        zeros = zero_ticks(bus.read_positions(robot.ids), robot)
        signs: dict[str, int] | None = None
        limits: dict[str, tuple[float, float]] | None = None
        if not args.zero:
            signs = _signs(bus, robot, ask)
            if args.limits:
                limits = _limits(bus, robot, zeros, signs, kind, ask)
    # A bundled robot's name would stay on the user's robot: it takes the file's name.
    name = out.stem if robot.name in robot_names() and out.stem != robot.name else None
    result = settle(robot, zeros, signs=signs, limits=limits, name=name)
    try:
        write_validated(source, out, result.changes(), name=name,
                        rest={jn: new for jn, (_, new) in result.rest.items()})
    except OSError as e:
        raise ConfigError(f"--out {out}: cannot write it: {e.strerror or e}; nothing was "
                          "written (free some space or choose another path)") from e
    check = " ".join(["biped monitor", "--robot", str(out), "--bus", kind, "--port",
                      args.port or robot.bus.port,
                      *(["--baud", str(args.baud)] if args.baud else [])])
    return report(robot, result, out, check=check)
