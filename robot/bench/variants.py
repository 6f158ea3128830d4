"""The 5-DoF variants of the bundled robots the studies walk (docs/gait.md, "Steering
without hip yaw"; docs/robots.md's recipe): the robot file without its two hip yaw
servos and the hip yaw link's mass, its knees on a stronger servo of the same bus (the
knee of a 5-DoF leg carries what the hip yaw servo's link did), and the heading loop's
``bal_stride_turn`` for that robot (docs/gait.md's table: 1 where ``turn`` > 0 turns the
variant left, 0 for the Feetech one, which walks at a third of its speed steered)."""

from __future__ import annotations

import re
from pathlib import Path

from robot.config.bundled import ROBOTS_DIR

#: Per bundled robot with hip yaw: its 5-DoF variant's knee servo and bal_stride_turn.
FIVE_DOF: dict[str, tuple[str, float]] = {
    "biped18-dynamixel": ("XM430-W350", 1.0),
    "biped18-feetech": ("STS3250", 0.0),
    "biped18-ax12": ("AX-18A", 1.0),
    "biped18-lx": ("LX-224", 1.0),
    "biped12-legs": ("XM430-W350", 1.0),
}


def five_dof_text(text: str, knee_model: str, stride_turn: float) -> str:
    """A robot file's ``text`` as its 5-DoF variant: no ``[joints.*_hip_yaw]`` tables, no
    ``hip_yaw_link`` mass, ``model = knee_model`` on both knees, ``bal_stride_turn`` set
    under ``[balance]`` (added if the file has none)."""
    s = re.sub(r"(?ms)^\[joints\.[rl]_hip_yaw\].*?(?=^\[)", "", text)
    s = re.sub(r"(?m)^hip_yaw_link = .*\n", "", s)
    for side in "rl":
        s = s.replace(f"[joints.{side}_knee]\n", f'[joints.{side}_knee]\nmodel = "{knee_model}"\n')
    line = f"bal_stride_turn = {stride_turn!r}\n"
    if re.search(r"(?m)^bal_stride_turn = ", s):
        return re.sub(r"(?m)^bal_stride_turn = .*\n", line, s)
    if re.search(r"(?m)^\[balance\]", s):
        return re.sub(r"(?m)^(\[balance\][^\n]*\n)", lambda m: m.group(1) + line, s, count=1)
    return s + f"\n[balance]\n{line}"


def write_five_dof(name: str, folder: Path) -> Path:
    """The 5-DoF variant of bundled robot ``name`` (a key of FIVE_DOF) written to
    ``folder``/<name>-5dof.toml; its path."""
    knee, turn = FIVE_DOF[name]
    path = folder / f"{name}-5dof.toml"
    path.write_text(five_dof_text((ROBOTS_DIR / f"{name}.toml").read_text(), knee, turn))
    return path
