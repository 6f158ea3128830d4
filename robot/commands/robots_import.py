"""`biped robots import MODEL --out my-robot.toml`: a URDF or MJCF model (onshape-to-robot,
fusion2urdf, a ROS description, a kit maker's) → a robot file that walks, in the sim, as
that model (docs/robots.md, "From CAD").

It prints what it found (legs and their layout, joints, mass, sole, offsets, servo ids,
every warning). Every joint it cannot place, every ambiguous role, every file it cannot
read: one line naming it, exit 2, and nothing written.
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

from robot.body.mjcf_read import read_mjcf
from robot.body.tree import BodyTree
from robot.config.model_import import build, check_servo, summary
from robot.config.model_recipe import read_map
from robot.config.model_text import robot_file_text
from robot.config.robot_file import parse_robot
from robot.errors import ConfigError
from robot.files.atomic import write_text
from robot.gait.ik_chain import check_layout
from robot.servo.models import BUS_FAMILIES, MODELS, factory_baud

MISSING = ("error", "box")
DEFAULT_MODEL = {"dynamixel": "XL430-W250", "dynamixel1": "AX-12A", "feetech": "STS3215",
                 "lx": "LX-16A"}


def add_import_parser(actions: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = actions.add_parser("import", help="a robot file from your URDF or MJCF model",
                           description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model_file", metavar="MODEL", help="the model: .urdf, or MJCF (.xml, .mjcf)")
    p.add_argument("--out", required=True, help="the robot file to write (.toml; never overwritten)")
    p.add_argument("--name", help="the robot's name (default: the --out file's name)")
    p.add_argument("--bus", choices=sorted(BUS_FAMILIES),
                   help="the servos' bus (default: the map's, else dynamixel)")
    p.add_argument("--model", dest="servo", help="the servo model (default: dynamixel "
                   "XL430-W250, feetech STS3215, dynamixel1 AX-12A, lx LX-16A)")
    p.add_argument("--baud", type=int, help="the bus baud rate (default: 1000000, or the "
                   "servo's only rate)")
    p.add_argument("--map", help="a TOML file naming joints by hand ([joints.MODEL_JOINT]: "
                   "servo_id, name, limits...) and the bus, gains and balance gains of the robot "
                   "(docs/robots.md, \"From CAD\")")
    p.add_argument("--mesh-dir", help="where package:// mesh paths are found (a URDF's)")
    p.add_argument("--missing-meshes", choices=MISSING, default="error",
                   help="a missing collision mesh: 'error' (default) names it; 'box' uses its "
                   "body's equivalent-inertia box instead, with a warning")
    p.add_argument("--fix-inertia", action="store_true", help="fix non-physical masses "
                   "and inertias (each fix is a warning saying how) instead of refusing them")
    p.add_argument("--source", default="", help="where the model comes from (kept in the file)")
    p.add_argument("--licence", default="", help="the model's licence (kept in the file)")
    return p


def read_model(path: Path, *, mesh_dir: str | None, missing: str, fix_inertia: bool
               ) -> tuple[BodyTree, list[str]]:
    """The body tree of a model file, by its suffix, and the reader's warnings."""
    suffix = path.suffix.lower()
    if not path.is_file():
        raise ConfigError(f"MODEL {path}: no such file")
    if suffix in (".urdf", ".xacro"):
        from robot.body.urdf_read import read_urdf

        return read_urdf(path, mesh_dir=mesh_dir, missing_mesh=missing, fix_inertia=fix_inertia)
    if suffix in (".xml", ".mjcf"):
        return read_mjcf(path, missing_mesh=missing, fix_inertia=fix_inertia)
    raise ConfigError(f"MODEL {path}: unknown model format {suffix or '(no suffix)'!r}; "
                      "valid: .urdf, .xacro, .xml, .mjcf")


def run_import(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if out.suffix != ".toml":
        raise ConfigError(f"--out {out}: expected a file name ending in .toml")
    if out.exists():
        raise ConfigError(f"--out {out}: exists; not overwritten: choose another name")
    if not out.parent.is_dir():
        raise ConfigError(f"--out {out}: directory {out.parent} does not exist")
    recipe = read_map(args.map)
    kind = args.bus or str(recipe.bus.get("kind", "dynamixel"))
    if kind not in BUS_FAMILIES:
        raise ConfigError(f"--map {args.map}: bus.kind: expected one of {', '.join(BUS_FAMILIES)}, "
                          f"got {kind!r}")
    servo = check_servo(kind, args.servo or str(recipe.bus.get("model", DEFAULT_MODEL[kind])))
    if servo.family not in BUS_FAMILIES[kind]:
        raise ConfigError(f"--model {servo.name}: not a {kind} servo; valid: "
                          f"{', '.join(m for m, s in MODELS.items() if s.family in BUS_FAMILIES[kind])}")
    path = Path(args.model_file)
    tree, warnings = read_model(path, mesh_dir=args.mesh_dir, missing=args.missing_meshes,
                                fix_inertia=args.fix_inertia)
    source, licence = args.source or recipe.source, args.licence or recipe.licence
    imp = build(tree, servo=servo, joint_map=recipe.joints, file=path.name,
                source=source, licence=licence, knee=recipe.knee)
    imp.warnings[:0] = warnings
    for leg in imp.model.legs:   # a leg the closed-form IK cannot solve is refused here
        check_layout(leg, where=str(path))
    baud = args.baud or int(recipe.bus.get("baud", 0)) or (  # type: ignore[call-overload]
        1_000_000 if 1_000_000 in _bauds(servo) else factory_baud(servo))
    name = args.name or out.stem
    header = [f"{name}: imported by `biped robots import` from {path.name}.",
              *([f"Model: {source}."] if source else []),
              *([f"Licence of the model: {licence}."] if licence else []),
              *recipe.notes,
              "The body ([model]) is the model's own numbers; docs/robots.md, \"From CAD\"."]
    text = robot_file_text(imp, name=name, kind=kind, servo=servo, baud=baud, header=header,
                           gains=recipe.gains, balance=recipe.balance, gait=recipe.gait)
    # What is written loads; a fault there comes from the map (a gain register, a value).
    parse_robot(tomllib.loads(text), source=f"{out} (from --map {args.map})" if args.map
                else str(out))
    for line in summary(imp, path=path):
        print(line)
    try:
        write_text(out, text)
    except OSError as e:
        raise ConfigError(f"--out {out}: cannot write it: {e.strerror or e}") from e
    print(f"wrote {out}: `biped walk --robot {out}` walks it in the sim")
    return 0


def _bauds(servo: object) -> list[int]:
    from robot.servo.models import bauds

    return bauds(servo.family)  # type: ignore[attr-defined]
