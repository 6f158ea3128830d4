"""`biped walk`: the main job. Default: the default robot and walk, on the MuJoCo bus,
headless, faster than real time, with a readable summary (or one JSON object)."""

from __future__ import annotations

import argparse
import json
import logging
from typing import Any

from robot.commands.balance_args import add_balance_args, imu_for
from robot.commands.common import (
    add_bus_args,
    add_robot_args,
    add_set_arg,
    bounded_int,
    bus_from,
    input_file,
    output_file,
    params_from,
    rate_hz,
    robot_from,
    seconds,
)
from robot.commands.model_args import add_model_names_arg, model_for
from robot.commands.switch_args import add_switch_arg, switches_from
from robot.commands.world_args import add_world_args, describe_world, world_from
from robot.config.read_back import MAX_READ_PERIOD_S, check_read_every, max_read_every
from robot.errors import ConfigError
from robot.motion.keyframes import load_sequence
from robot.run.result import TORQUE_WORDS
from robot.run.run import execute
from robot.run.spec import RunOptions
from robot.run.walk import HEADING_DRIFT_DEG_MIN, walk_spec, walk_summary

log = logging.getLogger(__name__)

#: --read-every: an integer in [1, the most any --rate allows] at parse time; the bound
#: at the run's rate is checked once the rate is known (robot.loop.watchdog).
read_every = bounded_int(1, max_read_every(2000.0), what="a read-back interval [ticks]")
#: Read back every 10th tick: 50 ms at the default 200 Hz.
READ_EVERY = 10


def add_walk_args(p: argparse.ArgumentParser) -> None:
    """Options shared by `walk` and `panel`."""
    add_robot_args(p)
    add_bus_args(p, default="sim")
    p.add_argument("--rate", type=rate_hz, default=200.0, help="control rate [Hz]")
    p.add_argument("--read-every", type=read_every, default=READ_EVERY, metavar="N",
                   help=f"read servos back every N ticks (default: {READ_EVERY}, fewer at "
                        f"a low --rate); at most {MAX_READ_PERIOD_S:g} s apart (N <= "
                        f"{MAX_READ_PERIOD_S:g} x --rate): the watchdog must see heat, "
                        "hardware errors and a jammed servo within about a second")
    p.add_argument("--hold", action="store_true",
                   help="hold the rest pose with torque on at the end (default: torque off)")
    p.add_argument("--realtime", action="store_true", help="pace the simulation to the wall clock")
    p.add_argument("--view", action="store_true", help="open the MuJoCo viewer (needs a display)")
    add_balance_args(p)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("walk", help="walk the robot (MuJoCo by default, or a real bus)")
    add_walk_args(p)
    p.add_argument("--seconds", type=seconds, default=10.0, help="gait duration [s]")
    p.add_argument("--record", type=output_file, metavar="PATH",
                   help="per-tick log (.csv or .jsonl: commanded and present joints, timing, "
                        "temperatures, loads), or a take to replay with `biped play` "
                        "(NAME.take.jsonl: the parameter timeline and the joint stream)")
    p.add_argument("--keyframes", type=input_file, metavar="FILE",
                   help="layer a keyframe sequence (.toml/.json) on the gait: its joints "
                        "(arms, extra joints) follow the keyframes while the legs walk")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--stop-on-fall", action="store_true",
                   help="sim: end the walk as soon as the robot falls (torque off at once, "
                        "as a fall detector on a real robot would)")
    add_model_names_arg(p)
    add_set_arg(p)
    add_switch_arg(p)
    add_world_args(p)
    return p


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    model = model_for(args, robot)
    gait, params = params_from(args, robot)
    switches = switches_from(args, robot)
    if gait.warning:
        log.warning("gait %r: %s", gait.name, gait.warning)
    kind = args.bus or "sim"
    if kind != "sim" and (args.view or args.realtime or args.stop_on_fall):
        raise ConfigError("--view, --realtime and --stop-on-fall apply to --bus sim only")
    world = world_from(args, kind)       # perturbations: sim only, None if none given
    options: dict[str, Any] = (
        {"realtime": args.realtime, "view": args.view} if kind == "sim" else {})
    if world is not None:
        options["world"] = world
    every = (min(READ_EVERY, max_read_every(args.rate)) if args.read_every == READ_EVERY
             else check_read_every(args.read_every, args.rate, where="--read-every"))
    bus = bus_from(args, robot, kind=kind, **options)
    imu = imu_for(args, robot, bus)
    layer = load_sequence(args.keyframes, robot) if args.keyframes else None
    spec = walk_spec(robot, params, bus, gait=gait.name, imu=imu, keyframes=layer,
                     record=args.record, options=RunOptions(
                         rate_hz=args.rate, read_every=every, hold=args.hold,
                         seconds=args.seconds, stop_on_fall=args.stop_on_fall, signals=True),
                     switches=switches, model=model)
    result = walk_summary(spec, execute(spec), gait=gait.name)
    if gait.warning:
        result["gait_warning"] = gait.warning
    if args.json:
        print(json.dumps(result))
    else:
        print(format_summary(result))
    return int(result["exit_code"])


def format_summary(r: dict[str, Any]) -> str:
    # An early stop (Ctrl-C, a fall, a fault) says how long it really ran, ramps included.
    ran = r["ticks"] / r["rate_hz"] if r.get("rate_hz") else 0.0
    span = (f"for {r['seconds']:g} s" if r["stop_reason"] == "completed"
            else f"for {ran:.1f} s of the {r['seconds']:g} s asked (stopped early)")
    lines = [f"{r['robot']} walked gait '{r['gait']}' {span} on the {r['bus']} bus"]
    if "distance_m" in r:
        fell = f"YES at {r['fell_at_s']:.1f} s" if r["fell"] else "no"
        lines += [
            f"  distance      {r['distance_m']:+.3f} m forward ({r['speed_m_s']:.3f} m/s)",
            f"  lateral drift {r['lateral_drift_m']:+.3f} m",
            f"  heading       {r['heading_change_deg']:+.1f} deg{heading_words(r)}",
            f"  fell          {fell} (lowest torso {r['min_torso_height_m']:.3f} m,"
            f" max tilt {r['max_tilt_deg']:.1f} deg)",
        ]
        feet = r.get("feet")
        if feet:
            lines.append(f"  feet          at least {feet['fewest_feet_down']} on the ground, flight "
                         f"{r.get('flight_s_per_cycle', 0.0) * 1e3:.0f} ms per cycle")
        if r.get("clamped_joints_s") or r.get("ik_unreachable_s") or r.get("speed_limited_joints_s"):
            lines.append(f"  joint limits  {clamp_words(r)}")
        world = describe_world(r.get("world"))
        if world:
            lines.append(f"  world         {world}")
    if r.get("switches"):
        lines.append("  switches      " + ", ".join(f"to {s['preset']} at {s['at_s']:g} s"
                                                   for s in r["switches"]))
    lines += [
        f"  loop          {r['ticks']} ticks at {r['rate_hz']:g} Hz"
        f" (achieved {r['achieved_hz']:.1f} Hz), period error"
        f" p50 {r['period_error_p50_ms']:.3f} ms, p99 {r['period_error_p99_ms']:.3f} ms,"
        f" {r['overruns']} overruns, {r['bus_errors']} bus errors",
        f"  realtime      x{r['realtime_factor']:.1f}",
        f"  stopped       {r['stop_reason']}",
        f"  servos        {servo_words(r['torque'])}",
    ]
    if r.get("record_error"):
        lines.append(f"  record        FAILED: {r['record_error']}")
    return "\n".join(lines)


def heading_words(r: dict[str, Any]) -> str:
    """What the summary says after the heading change: the asked turn and the drift beyond
    it per minute, flagged when it is more than robot.run.walk.HEADING_DRIFT_DEG_MIN."""
    if "heading_drift_deg_min" not in r:
        return ""
    asked = f"asked {r['heading_asked_deg']:+.1f} deg, " if r["heading_asked_deg"] else ""
    flag = (f": DRIFTS more than {HEADING_DRIFT_DEG_MIN:g} deg/min unasked"
            if r["heading_drifts"] else "")
    return f" ({asked}drift {r['heading_drift_deg_min']:+.1f} deg/min{flag})"


def clamp_words(r: dict[str, Any]) -> str:
    """Which joints the gait held at a limit and for how long, how long a target was out
    of the IK's reach, and which joints the loop held to their servo's speed."""
    held = ", ".join(f"{name} {t:.2f} s" for name, t in r["clamped_joints_s"].items())
    words = [f"held at a limit: {held}"] if held else []
    if r["ik_unreachable_s"]:
        words.append(f"target out of reach {r['ik_unreachable_s']:.2f} s")
    fast = ", ".join(f"{name} {t:.2f} s" for name, t in r.get("speed_limited_joints_s", {}).items())
    if fast:
        words.append(f"asked faster than the servo turns (held to its speed): {fast}")
    return "; ".join(words)


def servo_words(torque: str) -> str:
    """What the servos were left doing (LoopStats.torque), in the summary's words."""
    return "holding the rest pose, torque ON" if torque == "on" else TORQUE_WORDS[torque]
