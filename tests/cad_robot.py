"""A biped's URDF written for the tests in the style of onshape-to-robot: an empty root
link, frames as massless links on fixed joints, joint origins with odd rotations (the
axis then given in the rotated frame), ``package://`` mesh paths, a foot collision mesh
(an STL the test writes), the hip yaw axis 15 mm ahead of the roll-pitch point, the roll
axis 10 mm above the pitch axis, the legs' parts 12 mm outward along the pitch axes, the
ankle roll 8 mm below the ankle pitch, and the knees bent at the zero pose.

Every number is written here, in the model's terms: the tests' expectations come from
MuJoCo's own URDF parser on this file (or these numbers), never from the importer.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

#: The zero pose's bend: the thigh leans this much forward, the shin as much back [rad].
BEND = 0.3
THIGH = 0.10
SHIN = 0.10
#: The offsets of the leg's axes [m] (module docstring).
YAW_AHEAD = 0.015
ROLL_DROP = 0.010
LATERAL = 0.012
ANKLE_DROP = 0.008
SOLE_BELOW = 0.030
FOOT = (0.10, 0.05, 0.01)     # the sole mesh: a box [m]
FOOT_AHEAD = 0.012            # its centre ahead of the ankle [m]


def box_stl(size: tuple[float, float, float]) -> bytes:
    """A binary STL of a box of full ``size`` [m] centred on its origin."""
    sx, sy, sz = (s / 2 for s in size)
    v = [(x, y, z) for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    out = bytearray(b"\0" * 80 + struct.pack("<I", len(faces)))
    for f in faces:
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for k in f:
            out += struct.pack("<3f", *v[k])
        out += b"\0\0"
    return bytes(out)


def _inertial(mass: float, size: tuple[float, float, float], xyz: str = "0 0 0") -> str:
    a, b, c = size
    return (f'<inertial><origin xyz="{xyz}" rpy="0 0 0"/><mass value="{mass}"/>'
            f'<inertia ixx="{mass * (b * b + c * c) / 12}" iyy="{mass * (a * a + c * c) / 12}" '
            f'izz="{mass * (a * a + b * b) / 12}" ixy="0" ixz="0" iyz="0"/></inertial>')


def _link(name: str, mass: float, size: tuple[float, float, float], *, xyz: str = "0 0 0",
          collide: bool = True, extra: str = "") -> str:
    col = (f'<collision><origin xyz="{xyz}" rpy="0 0 0"/><geometry><box size="'
           f'{size[0]} {size[1]} {size[2]}"/></geometry></collision>') if collide else ""
    return (f'<link name="{name}">{_inertial(mass, size, xyz)}<visual><geometry><mesh '
            f'filename="package://cad_robot/assets/{name}_visual.stl"/></geometry></visual>'
            f'{col}{extra}</link>')


def _joint(name: str, parent: str, child: str, xyz: str, rpy: str, axis: str, lo: float,
           hi: float) -> str:
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="{lo}" upper="{hi}" effort="1.5" velocity="6.0"/></joint>')


def _leg(side: str) -> list[str]:
    s = 1.0 if side == "left" else -1.0
    kx, kz = THIGH * math.sin(BEND), -THIGH * math.cos(BEND)   # knee from the hip pitch
    ax, az = -SHIN * math.sin(BEND), -SHIN * math.cos(BEND)     # ankle from the knee
    out = [
        _link(f"{side}_hip_yaw_link", 0.05, (0.03, 0.03, 0.03)),
        _link(f"{side}_hip_roll_link", 0.08, (0.04, 0.03, 0.03)),
        # the thigh's frame is turned (rpy below): the world's z is its -y, y its z
        _link(f"{side}_thigh_link", 0.12, (0.03, THIGH, 0.03), xyz=f"{kx / 2} {-kz / 2} 0"),
        # the shin's frame is upside down: the world's z is its -z
        _link(f"{side}_shin_link", 0.10, (0.03, 0.03, SHIN), xyz=f"{ax / 2} 0 {-az / 2}"),
        _link(f"{side}_ankle_link", 0.05, (0.03, 0.03, 0.03)),
        (f'<link name="{side}_foot_link">{_inertial(0.08, FOOT, f"{FOOT_AHEAD} 0 {-SOLE_BELOW + 0.005}")}'
         f'<collision><origin xyz="{FOOT_AHEAD} 0 {-SOLE_BELOW + FOOT[2] / 2}" rpy="0 0 0"/>'
         f'<geometry><mesh filename="package://cad_robot/assets/Foot_Sole.STL"/></geometry>'
         f'</collision></link>'),
        f'<link name="{side}_foot_frame"/>',
        _joint(f"{side}_hip_yaw", "trunk", f"{side}_hip_yaw_link", f"0 {s * 0.045} -0.02",
               "0 0 0", "0 0 1", -0.6, 0.6),
        # the roll axis 15 mm behind and 25 mm below the yaw origin; its frame turned
        # upside down (rpy pi 0 0), so its x axis still runs forward: axis "1 0 0"
        _joint(f"{side}_hip_roll", f"{side}_hip_yaw_link", f"{side}_hip_roll_link",
               f"{-YAW_AHEAD} 0 -0.025", f"{math.pi} 0 0", "1 0 0", -0.5, 0.5),
        # the pitch axis 10 mm below the roll axis, 12 mm outward (in the flipped frame:
        # z up is -z, y left is -y); its frame turned a quarter about x: axis "0 0 -1"
        _joint(f"{side}_hip_pitch", f"{side}_hip_roll_link", f"{side}_thigh_link",
               f"0 {-s * LATERAL} {ROLL_DROP}", f"{math.pi / 2} 0 0", "0 0 -1", -1.6, 0.8),
    ]
    # the thigh's frame is Rx(-pi/2) in the world: the knee's offset written in it
    out += [
        _joint(f"{side}_knee", f"{side}_thigh_link", f"{side}_shin_link",
               f"{kx} {-kz} 0", f"{-math.pi / 2} 0 0", "0 -1 0", -0.3, 2.4),
    ]
    # the shin's frame is Rx(pi) in the world: the ankle 'below' is +z in it
    out += [
        _joint(f"{side}_ankle_pitch", f"{side}_shin_link", f"{side}_ankle_link",
               f"{ax} {0.0} {-az}", "0 0 0", "0 -1 0", -1.2, 1.2),
        _joint(f"{side}_ankle_roll", f"{side}_ankle_link", f"{side}_foot_link",
               f"0 0 {ANKLE_DROP}", f"{math.pi} 0 0", "1 0 0", -0.5, 0.5),
        f'<joint name="{side}_foot_fixed" type="fixed"><parent link="{side}_foot_link"/>'
        f'<child link="{side}_foot_frame"/><origin xyz="0 0 {-SOLE_BELOW}" rpy="0 0 0"/></joint>',
    ]
    return out


def _arm(side: str) -> list[str]:
    s = 1.0 if side == "left" else -1.0
    return [
        _link(f"{side}_shoulder_link", 0.03, (0.03, 0.03, 0.03)),
        _link(f"{side}_upper_arm_link", 0.06, (0.03, 0.03, 0.08), xyz="0 0 -0.04"),
        _link(f"{side}_forearm_link", 0.05, (0.03, 0.03, 0.09), xyz="0 0 -0.045"),
        _joint(f"{side}_shoulder_pitch", "trunk", f"{side}_shoulder_link", f"0 {s * 0.09} 0.14",
               "0 0 0", "0 1 0", -3.0, 1.5),
        _joint(f"{side}_shoulder_roll", f"{side}_shoulder_link", f"{side}_upper_arm_link",
               "0 0 0", "0 0 0", "1 0 0", -1.6, 1.6),
        _joint(f"{side}_elbow", f"{side}_upper_arm_link", f"{side}_forearm_link",
               "0 0 -0.08", "0 0 0", "0 1 0", -2.2, 0.1),
    ]


def urdf(name: str = "cad_robot") -> str:
    parts = [f'<?xml version="1.0"?>\n<robot name="{name}">',
             '<link name="base_link"/>',
             _link("trunk", 0.7, (0.08, 0.14, 0.16), xyz="0 0 0.07"),
             '<joint name="base_to_trunk" type="fixed"><parent link="base_link"/>'
             '<child link="trunk"/><origin xyz="0 0 0" rpy="0 0 0"/></joint>',
             '<link name="imu_frame"/><joint name="imu_fixed" type="fixed"><parent link="trunk"/>'
             '<child link="imu_frame"/><origin xyz="0 0 0.05" rpy="0 0 0"/></joint>']
    for side in ("right", "left"):
        parts += _leg(side)
    for side in ("right", "left"):
        parts += _arm(side)
    parts.append("</robot>")
    return "\n".join(parts) + "\n"


def write(folder: Path) -> tuple[Path, Path]:
    """The URDF and its mesh folder (the package root for --mesh-dir) under ``folder``."""
    pkg = folder / "cad_robot"
    (pkg / "assets").mkdir(parents=True, exist_ok=True)
    (pkg / "assets" / "Foot_Sole.STL").write_bytes(box_stl(FOOT))
    path = folder / "robot.urdf"
    path.write_text(urdf(), encoding="utf-8")
    return path, folder
