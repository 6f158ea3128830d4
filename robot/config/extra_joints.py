"""Where a robot's extra joints (beyond the legs and arms: a head pan and tilt, a jaw, a
tail) sit and which way they turn, from their names: one layout that the BVH and glTF
skeletons (robot/previs/bvh.py) and the box model (robot/body/boxes.py, through
robot/config/body_tree.py) share.

Axis (robot frame, right-hand rule): a name with ``tilt``, ``pitch``, ``nod`` or ``jaw``
turns about y (nodding); with ``roll``, about x; anything else (``pan``, ``yaw``,
``tail``, ``waist``...) about z. Place: joints whose names start alike (``head_pan``,
``head_tilt``) form a chain in the robot file's order, each one a link above the last; a
chain starts on top of the torso (a neck), except ``tail...`` at the back of the pelvis
(each link further back) and ``jaw...``, hung in front of the end of the head chain when
there is one. Offsets are in the parent joint's frame at zero pose [m].
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from robot.config.joint_names import JOINT_NAMES
from robot.config.robot import RobotConfig

PITCH_WORDS = ("tilt", "pitch", "nod", "jaw")
ROLL_WORDS = ("roll",)
#: Vector of the robot axis names.
UNIT = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class ExtraJoint:
    """name; axis: "x", "y" or "z"; parent: the extra joint it sits on (None: the torso,
    at the pelvis origin); offset [m] from the parent; kind: "neck", "head", "jaw" or
    "tail" (what the simulation draws)."""

    name: str
    axis: str
    parent: str | None
    offset: tuple[float, float, float]
    kind: str


def extra_axis(name: str) -> str:
    words = name.lower()
    if any(w in words for w in PITCH_WORDS):
        return "y"
    if any(w in words for w in ROLL_WORDS):
        return "x"
    return "z"


def link_length(robot: RobotConfig) -> float:
    """Spacing of the joints in a chain [m]: a fifth of the torso's height."""
    return 0.2 * robot.geometry.torso_height


def extra_layout(robot: RobotConfig) -> tuple[ExtraJoint, ...]:
    """The extra joints of ``robot`` in its joint order, each placed and oriented."""
    g = robot.geometry
    link = link_length(robot)
    extras = [j.name for j in robot.joints if j.name not in JOINT_NAMES]
    last: dict[str, str] = {}            # chain prefix → its last joint so far
    out: list[ExtraJoint] = []
    for name in extras:
        prefix = name.split("_")[0]
        before = last.get(prefix)
        if prefix.startswith("tail"):
            offset = (-link, 0.0, 0.0) if before else (-g.torso_depth / 2, 0.0, 0.0)
            kind = "tail"
        elif prefix.startswith("jaw") and before is None and "head" in last:
            before, offset, kind = last["head"], (0.6 * link, 0.0, 0.3 * link), "jaw"
        else:
            offset = (0.0, 0.0, link) if before else (0.0, 0.0, g.torso_height + link)
            kind = "jaw" if prefix.startswith("jaw") else "neck"
        out.append(ExtraJoint(name, extra_axis(name), before, offset, kind))
        last[prefix] = name
    tops = {end for prefix, end in last.items() if not prefix.startswith(("tail", "jaw"))}
    return tuple(replace(e, kind="head") if e.name in tops else e for e in out)
