"""The joints the gait drives, by name (sides r/l; legs then arms), and the rules for the
joints a robot file may have: every leg joint (hip yaw or ankle roll optional, on both
sides: 5-DoF legs; not both), all arm joints or none, and extra joints (head pan, tilt, ...) held at a fixed
angle."""

from __future__ import annotations

import re

SIDES = ("r", "l")
LEG_JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
ARM_JOINTS = ("shoulder_pitch", "shoulder_roll", "elbow")
LEG_NAMES = tuple(f"{s}_{j}" for s in SIDES for j in LEG_JOINTS)
ARM_NAMES = tuple(f"{s}_{j}" for s in SIDES for j in ARM_JOINTS)
JOINT_NAMES = LEG_NAMES + ARM_NAMES
HIP_YAW_NAMES = ("r_hip_yaw", "l_hip_yaw")
ANKLE_ROLL_NAMES = ("r_ankle_roll", "l_ankle_roll")
#: Names of extra joints: lowercase letters, digits and '_', starting with a letter.
EXTRA_NAME = re.compile(r"^[a-z][a-z0-9_]{0,31}\Z")  # \Z: "$" lets a final newline in


def limb_groups(names: tuple[str, ...] | list[str]) -> list[tuple[str, list[str]]]:
    """``names`` by limb, for plots: ("leg joints", ...), ("arm joints", ...), ("extra
    joints", ...): the non-empty groups, each in the given order."""
    groups = (("leg joints", [n for n in names if n in LEG_NAMES]),
              ("arm joints", [n for n in names if n in ARM_NAMES]),
              ("extra joints", [n for n in names if n not in JOINT_NAMES]))
    return [(label, group) for label, group in groups if group]
