"""The real kits' published models (../shared/robots/, unchanged downloads) as the tests'
independent oracle: MuJoCo compiles the vendor's own file, its meshes left out (the
downloads lack most of them; they move no joint)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco

ROBOTS = Path(__file__).resolve().parents[1].parent / "shared" / "robots"
OP3 = ROBOTS / "robotis_op3" / "op3.xml"
DUCK = ROBOTS / "open_duck_mini_v2" / "robot.xml"
#: Bundled robot → the published model it was imported from.
KITS = {"robotis-op3": OP3, "open-duck-mini-v2": DUCK}


def without_meshes(path: Path) -> mujoco.MjModel:
    """The model with its mesh assets and mesh geoms left out (the kinematics stay)."""
    root = ET.parse(path).getroot()
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag == "mesh" or (child.tag == "geom" and (child.get("mesh") or
                                                                child.get("type") == "mesh")):
                parent.remove(child)
    return mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
