"""Change a few joint values of a robot TOML file, keeping its comments and layout (tomlkit).

``edit_joints(text, {joint: {field: value}})`` returns the new text (optionally also the
robot's ``name`` and ``[rest]`` angles); the caller validates it with
``robot.config.robot_file.parse_robot`` before writing. ``write_validated`` does both:
nothing is written unless the result loads.
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from pathlib import Path

import tomlkit
from tomlkit.exceptions import TOMLKitError

from robot.config.robot import RobotConfig
from robot.config.robot_file import parse_robot
from robot.errors import ConfigError
from robot.files.atomic import write_text

EDITABLE = ("sign", "zero_ticks", "min_rad", "max_rad", "fixed_rad")


def edit_joints(text: str, changes: Mapping[str, Mapping[str, int | float]], *,
                source: str = "<robot>", name: str | None = None,
                rest: Mapping[str, float] | None = None) -> str:
    """``text`` with ``joints.<joint>.<field>`` set for every entry of ``changes``, and
    ``name`` and ``rest.<joint>`` [rad] when given."""
    try:
        doc = tomlkit.parse(text)
    except TOMLKitError as e:
        raise ConfigError(f"{source}: not valid TOML: {e}") from e
    joints = doc.get("joints")
    for joint, fields in changes.items():
        table = joints.get(joint) if joints is not None else None
        if table is None:
            raise ConfigError(f"{source}: joints.{joint}: missing; cannot set "
                              f"{', '.join(fields)}")
        for key, value in fields.items():
            if key not in EDITABLE:
                raise ValueError(f"edit_joints: {key!r} is not one of {EDITABLE}")
            table[key] = value
    if name is not None:
        doc["name"] = name
    for joint, q in (rest or {}).items():
        doc["rest"][joint] = q
    return tomlkit.dumps(doc)


def same_path(a: str | Path, b: str | Path) -> bool:
    """Whether ``a`` and ``b`` name the same file (symlinks and relative paths resolved)."""
    pa, pb = Path(a), Path(b)
    if pa.exists() and pb.exists():
        return os.path.samefile(pa, pb)
    return pa.resolve() == pb.resolve()


def write_validated(source: Path, out: Path,
                    changes: Mapping[str, Mapping[str, int | float]], *,
                    name: str | None = None,
                    rest: Mapping[str, float] | None = None) -> RobotConfig:
    """Write ``source`` with ``changes`` (and ``name``, ``rest``: see ``edit_joints``) to
    ``out`` (atomically) if the result is a valid robot file; ConfigError naming ``out``,
    its field and the fix otherwise (nothing written)."""
    text = edit_joints(source.read_text(encoding="utf-8"), changes, source=str(source),
                       name=name, rest=rest)
    robot = parse_robot(tomllib.loads(text), source=str(out))
    write_text(out, text)
    return robot
