"""`biped robots`: the bundled robot files, to pick one or to start your own from.

``biped robots`` lists every bundled robot: its bus, servos and joints (``--json``: one JSON
list). ``biped robots copy NAME DEST`` writes the bundled file NAME to DEST (a new ``.toml``
file, or an existing directory: DEST/NAME.toml), comments and all, with its ``name`` set to
the new file's name. It never overwrites; every refusal is one line and exit code 2.
"""

from __future__ import annotations

import argparse
import json
import tomllib
from collections import Counter
from pathlib import Path

from robot.commands.common import one_line_errors
from robot.commands.robots_import import add_import_parser, run_import
from robot.config.bundled import ROBOTS_DIR, robot_names
from robot.config.joint_names import ARM_NAMES, LEG_NAMES
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot, parse_robot
from robot.config.toml_edit import edit_joints
from robot.errors import ConfigError
from robot.files.atomic import write_text


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("robots", help="list the bundled robots; copy one to start "
                              "your own", description=__doc__)
    p.add_argument("--json", action="store_true", help="print one JSON list and nothing else")
    actions = p.add_subparsers(dest="action", metavar="ACTION")
    c = actions.add_parser("copy", help="copy a bundled robot file to start your own from",
                           description="Write the bundled robot NAME to DEST, named after "
                           "DEST; never overwrites.")
    c.add_argument("name", metavar="NAME", help=f"a bundled robot ({', '.join(robot_names())})")
    c.add_argument("dest", metavar="DEST",
                   help="the new file (ending in .toml), or an existing directory")
    one_line_errors(c)
    one_line_errors(add_import_parser(actions))
    return one_line_errors(p)


def about(path: Path) -> str:
    """The first sentence of the file's opening comment (what the robot is)."""
    lines = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    text = " ".join(lines)
    return text.split(". ", 1)[0].rstrip(".") + "." if text else ""


def describe(name: str, robot: RobotConfig) -> dict[str, object]:
    """One bundled robot for the listing: bus, servo models and counts, joints."""
    servos = Counter(robot.servo(j).name for j in robot.joints)
    return {
        "name": name, "file": str(ROBOTS_DIR / f"{name}.toml"),
        "about": about(ROBOTS_DIR / f"{name}.toml"),
        "bus": robot.bus.kind, "baud": robot.bus.baud,
        "servos": dict(servos.most_common()),
        "joints": [{"name": j.name, "servo_id": j.servo_id, "model": robot.servo(j).name}
                   for j in robot.joints],
    }


def _joints(robot: RobotConfig) -> str:
    """``18: legs 2 x 6, arms 2 x 3`` (and any extra joint by name)."""
    names = robot.joint_names
    legs = sum(n in LEG_NAMES for n in names)
    parts = [f"legs 2 x {legs // 2}"]
    if robot.has_arms:
        parts.append(f"arms 2 x {len(ARM_NAMES) // 2}")
    parts += [n for n in names if n not in LEG_NAMES and n not in ARM_NAMES]
    return f"{len(names)}: {', '.join(parts)}"


def _list(as_json: bool) -> None:
    robots = {name: load_robot(name) for name in robot_names()}
    if as_json:
        print(json.dumps([describe(name, r) for name, r in robots.items()], indent=2))
        return
    print(f"{'name':<20} {'bus':<11} {'baud':>8}  {'servos':<24} joints")
    for name, robot in robots.items():
        count = Counter(robot.servo(j).name for j in robot.joints)
        servos = ", ".join(f"{n} x {m}" for m, n in count.most_common())
        print(f"{name:<20} {robot.bus.kind:<11} {robot.bus.baud:>8}  {servos:<24} "
              f"{_joints(robot)}")
    print("start your own: biped robots copy NAME my-robot.toml (then docs/robots.md, "
          "biped setup-motors, biped calibrate)")


def copy(name: str, dest: Path) -> Path:
    """Write the bundled robot ``name`` to ``dest`` (or ``dest/name.toml``), named after the
    new file; the path written. ConfigError (one line) when it exists or cannot be made."""
    if name not in robot_names():
        raise ConfigError(f"copy NAME {name!r}: not a bundled robot; valid: "
                          f"{', '.join(robot_names())}")
    target = dest / f"{name}.toml" if dest.is_dir() else dest
    if target.suffix != ".toml":
        raise ConfigError(f"copy DEST {str(dest)!r}: expected a file name ending in .toml "
                          "(so --robot reads it as a path), or an existing directory")
    if not target.parent.is_dir():
        raise ConfigError(f"copy DEST {dest}: directory {target.parent} does not exist; "
                          "create it first or choose another path")
    text = edit_joints((ROBOTS_DIR / f"{name}.toml").read_text(encoding="utf-8"), {},
                       name=target.stem)
    parse_robot(tomllib.loads(text), source=str(target))    # the copy loads as it is
    try:
        write_text(target, text, exclusive=True)
    except FileExistsError:
        raise ConfigError(f"copy DEST {target}: exists; not overwritten: choose another "
                          "name, or delete it first") from None
    except OSError as e:             # e.g. a full disk: no half-written robot file is left
        raise ConfigError(f"copy DEST {target}: cannot write it: {e.strerror or e}; "
                          "nothing was left there") from e
    return target


def run(args: argparse.Namespace) -> int:
    if args.action == "import":
        return run_import(args)
    if args.action != "copy":
        _list(args.json)
        return 0
    target = copy(args.name, Path(args.dest))
    renamed = f", named {target.stem!r}" if target.stem != args.name else ""
    print(f"wrote {target}: the bundled {args.name}{renamed}; make it yours (docs/robots.md), "
          f"then `biped setup-motors --robot {target}` and `biped calibrate --robot {target} "
          f"--out {target} --overwrite`")
    return 0
