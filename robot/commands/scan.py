"""`biped scan`: list the servos on a bus, map them to the robot's joints, flag what is off.

Exit status 1 when a joint of the robot file did not answer (the table names them)."""

from __future__ import annotations

import argparse
import json
import logging

from robot.bus import health
from robot.bus.base import ServoInfo
from robot.bus.sdk.bus import SdkBus
from robot.commands.common import HARDWARE_BUSES, add_bus_args, bus_from, id_list, one_line_errors
from robot.config.bundled import DEFAULT_ROBOT, ROBOTS_DIR, robot_names
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import BusError
from robot.setup.monitor_table import gains_lines

log = logging.getLogger(__name__)


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("scan", help="list the servos on a Dynamixel or Feetech bus",
                              description=__doc__)
    add_bus_args(p, choices=HARDWARE_BUSES)
    p.add_argument("--ids", type=id_list, default=None, metavar="RANGE",
                   help="ids to ping, e.g. 1-20 or 1,3,5-7 (default: 1-20 and the robot's ids)")
    p.add_argument("--robot", default=None, metavar="PATH",
                   help="robot TOML whose joints to match (default: the bundled robot for --bus)")
    p.add_argument("--json", action="store_true", help="print one JSON list and nothing else")
    p.add_argument("--fix-return-delay", action="store_true",
                   help="set return_delay_time = 0 on every servo found (torque off)")
    return one_line_errors(p)


def _robot(args: argparse.Namespace) -> RobotConfig:
    if args.robot:
        return load_robot(args.robot)
    if args.bus:
        bundled = ROBOTS_DIR / f"biped18-{args.bus}.toml"
        if bundled.exists():
            return load_robot(bundled)
        for name in robot_names():       # a bundled robot on that bus (dynamixel1: the AX's)
            robot = load_robot(ROBOTS_DIR / f"{name}.toml")
            if robot.bus.kind == args.bus:
                return robot
    return load_robot(DEFAULT_ROBOT)


def _row(info: ServoInfo, robot: RobotConfig,
         gains: dict[str, int] | None = None) -> dict[str, object]:
    joint = robot.joint_by_id(info.id)
    return {"id": info.id, "model": info.model, "model_name": info.model_name,
            "firmware": info.firmware, "return_delay_us": info.return_delay_us,
            "baud": info.baud, "joint": joint.name if joint else None, "gains": gains,
            "case": joint.case if joint else None}


def run(args: argparse.Namespace) -> int:
    robot = _robot(args)
    ids = args.ids or sorted(set(range(1, 21)) | set(robot.ids))
    bus = bus_from(args, robot, check_health=False)
    bus.open()
    try:
        found = bus.scan(ids)
        if not found and isinstance(bus, SdkBus):
            raise health.wrong_baud_error(bus, ids)
        if args.fix_return_delay and isinstance(bus, SdkBus):
            changed = health.fix_return_delay(bus, [s.id for s in found])
            log.warning("return delay set to 0 on ids %s", changed or "none (all were 0)")
            found = bus.scan([s.id for s in found])
        gains = {s.id: bus.read_gains(s.id, model=s.model) for s in found}
    except BusError:
        bus.close(torque_off=False)
        raise
    bus.close(torque_off=False)
    rows = [_row(info, robot, gains[info.id]) for info in found]
    seen = {r["id"] for r in rows}
    incomplete = 1 if any(j.servo_id not in seen for j in robot.joints) else 0
    if args.json:
        print(json.dumps(rows))
        return incomplete
    _print_table(rows, robot, bus_name=f"{bus.kind} {args.port or robot.bus.port}",
                 gains_text=gains_lines({f"id {sid}": g for sid, g in gains.items()}))
    return incomplete   # exit 1: a joint of the robot file did not answer


def _print_table(rows: list[dict[str, object]], robot: RobotConfig, *, bus_name: str,
                 gains_text: list[str]) -> None:
    print(f"{len(rows)} servo(s) on {bus_name}:")
    print(f"{'id':>4}  {'model':<18} {'fw':>4} {'delay':>8}  joint ({robot.name})")
    for r in rows:
        model = f"{r['model_name']} ({r['model']})"
        delay = f"{r['return_delay_us']:.0f} µs" if r["return_delay_us"] is not None else "?"
        joint = r["joint"] or "(not in robot config)"
        if r["case"]:
            joint = f"{joint} (axis of dual case {r['case']})"
        print(f"{r['id']:>4}  {model:<18} {r['firmware'] or '?':>4} {delay:>8}  {joint}")
    print("\n".join(gains_text))
    seen = {r["id"] for r in rows}
    missing = [j for j in robot.joints if j.servo_id not in seen]
    if missing:
        print(f"missing joints ({len(missing)} of {len(robot.joints)}; exit status 1): "
              + ", ".join(f"{j.name} (id {j.servo_id})" for j in missing))
    slow = [r["id"] for r in rows if r["return_delay_us"]]
    if slow:
        print(f"return delay > 0 on ids {slow}: rerun with --fix-return-delay")
